#include "nphand/motion/gltf_motion.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "nphand/model/gltf_accessor.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "nphand/util/version.h"

namespace nphand {
namespace {

constexpr const char* kMeshCopyright =
    "generic-hand mesh: Copyright (c) 2019 Amazon, MIT License (@webxr-input-profiles/assets 1.0.20; the licence "
    "travels with nphand in share/nphand/hand/LICENSE.md). Animation: estimated by nphand.";

tinygltf::Model Parse(std::span<const uint8_t> glb, const std::string& source) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model gltf;
  std::string error, warning;
  const bool ok =
      loader.LoadBinaryFromMemory(&gltf, &error, &warning, glb.data(), static_cast<unsigned int>(glb.size()));
  NPHAND_THROW_CHECK(ok, source, ": not a readable binary glTF (", error, ")");
  return gltf;
}

// The node of each joint of the generic hand, by the names of the one skin's joints.
std::array<int, kNumJoints> JointNodes(const tinygltf::Model& gltf, const std::string& source) {
  NPHAND_THROW_CHECK(gltf.skins.size() == 1, source, ": expected one skin, found ", gltf.skins.size());
  const std::vector<int>& joints = gltf.skins[0].joints;
  NPHAND_THROW_CHECK(joints.size() == kNumJoints, source, ": expected ", kNumJoints, " joints, found ", joints.size());
  std::array<int, kNumJoints> nodes;
  nodes.fill(-1);
  for (int node : joints) {
    NPHAND_THROW_CHECK(node >= 0 && node < static_cast<int>(gltf.nodes.size()), source, ": a skin joint names a missing node");
    for (int j = 0; j < kNumJoints; ++j) {
      if (gltf.nodes[node].name == JointName(static_cast<Joint>(j))) nodes[j] = node;
    }
  }
  for (int j = 0; j < kNumJoints; ++j) {
    NPHAND_THROW_CHECK(nodes[j] >= 0, source, ": no joint '", JointName(static_cast<Joint>(j)), "'");
  }
  return nodes;
}

// Each node's parent (-1 for a root); throws for a node with two parents.
std::vector<int> NodeParents(const tinygltf::Model& gltf, const std::string& source) {
  std::vector<int> parents(gltf.nodes.size(), -1);
  for (size_t n = 0; n < gltf.nodes.size(); ++n) {
    for (int child : gltf.nodes[n].children) {
      NPHAND_THROW_CHECK(child >= 0 && child < static_cast<int>(gltf.nodes.size()) && parents[child] < 0 &&
                             child != static_cast<int>(n),
                         source, ": node ", n, " has an invalid child ", child);
      parents[child] = static_cast<int>(n);
    }
  }
  return parents;
}

struct Trs {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Affine3d Matrix() const {
    return Eigen::Translation3d(translation) * rotation.normalized() * Eigen::Scaling(scale);
  }
};

Trs NodeTrs(const tinygltf::Node& node, const std::string& source) {
  NPHAND_THROW_CHECK(node.matrix.empty(), source, ": node '", node.name, "' is given by a matrix, not by TRS");
  Trs trs;
  if (node.translation.size() == 3) trs.translation = Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  if (node.rotation.size() == 4) {
    trs.rotation = Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
  }
  if (node.scale.size() == 3) trs.scale = Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]);
  return trs;
}

// Appends `values` to the glb's one buffer as a new view and accessor of `count` elements.
int AddAccessor(tinygltf::Model* gltf, const std::vector<float>& values, int type, size_t count) {
  std::vector<unsigned char>& data = gltf->buffers[0].data;
  while (data.size() % 4 != 0) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = values.size() * sizeof(float);
  const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
  data.insert(data.end(), bytes, bytes + view.byteLength);
  gltf->bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(gltf->bufferViews.size()) - 1;
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.type = type;
  accessor.count = count;
  gltf->accessors.push_back(accessor);
  return static_cast<int>(gltf->accessors.size()) - 1;
}

void AddChannel(tinygltf::Animation* animation, int node, const char* path, int input, int output) {
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation->samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(animation->samplers.size()) - 1;
  channel.target_node = node;
  channel.target_path = path;
  animation->channels.push_back(channel);
}

}  // namespace

std::vector<uint8_t> GltfMotionBytes(const HandModel& hand, std::span<const uint8_t> asset_glb, const Motion& motion) {
  NPHAND_THROW_CHECK(hand.handedness() == motion.hand, "glTF: a ", ToString(motion.hand),
                     " hand's motion was given the ", ToString(hand.handedness()), " hand model");
  NPHAND_THROW_CHECK(!motion.frames.empty(), "glTF: the motion has no frames");
  const std::string source = "the " + ToString(hand.handedness()) + " hand asset";
  tinygltf::Model gltf = Parse(asset_glb, source);
  const std::array<int, kNumJoints> nodes = JointNodes(gltf, source);
  const std::vector<int> parents = NodeParents(gltf, source);
  // The joints hang from one node that does not move them (the asset's "Armature").
  const int root = parents[nodes[0]];
  NPHAND_THROW_CHECK(root >= 0, source, ": the wrist has no parent node");
  for (int node : nodes) NPHAND_THROW_CHECK(parents[node] == root, source, ": the joints do not share one parent");
  const Trs root_trs = NodeTrs(gltf.nodes[root], source);
  NPHAND_THROW_CHECK(root_trs.Matrix().isApprox(Eigen::Affine3d::Identity(), 1e-9), source,
                     ": the skeleton's root node moves it");
  NPHAND_THROW_CHECK(gltf.buffers.size() == 1 && gltf.buffers[0].uri.empty(), source, ": expected one embedded buffer");
  const double s = motion.scale;
  if (s != 1.0) gltf.nodes[root].scale = {s, s, s};

  // The tip joints' nodes are put at the fingertip keypoints, the fingers' ends, their
  // inverse bind matrices with them (the joints hang from an identity root, so a node's
  // rest transform is its bind pose). They move no skin, so the mesh is as it was.
  const tinygltf::Skin& skin = gltf.skins[0];
  ReadAccessor<float>(gltf, skin.inverseBindMatrices, TINYGLTF_COMPONENT_TYPE_FLOAT, 16, source,
                      "inverse bind matrices");  // checks that they lie within their buffer
  const tinygltf::Accessor& binds = gltf.accessors[skin.inverseBindMatrices];
  const tinygltf::BufferView& view = gltf.bufferViews[binds.bufferView];
  for (size_t slot = 0; slot < skin.joints.size(); ++slot) {
    const int j = static_cast<int>(std::find(nodes.begin(), nodes.end(), skin.joints[slot]) - nodes.begin());
    if (!IsTipJoint(j)) continue;
    NPHAND_THROW_CHECK(hand.VerticesMovedBy(j, 1e-6f).empty(), source, ": its joint '",
                       JointName(static_cast<Joint>(j)), "' moves skin");
    const Eigen::Vector3d tip = hand.hand_from_mesh().inverse() * hand.bind_keypoints()[JointKeypoint(j)];
    tinygltf::Node& node = gltf.nodes[skin.joints[slot]];
    node.translation = {tip.x(), tip.y(), tip.z()};
    const Eigen::Matrix4f bind = NodeTrs(node, source).Matrix().inverse().matrix().cast<float>();  // column-major
    const size_t stride = view.byteStride != 0 ? view.byteStride : sizeof(float) * 16;
    std::memcpy(gltf.buffers[view.buffer].data.data() + view.byteOffset + binds.byteOffset + slot * stride,
                bind.data(), sizeof(float) * 16);
  }
  std::array<Trs, kNumJoints> rest;
  std::array<Eigen::Isometry3d, kNumJoints> joint_from_hand;
  for (int j = 0; j < kNumJoints; ++j) {
    rest[j] = NodeTrs(gltf.nodes[nodes[j]], source);
    Eigen::Isometry3d hand_from_joint = Eigen::Isometry3d::Identity();
    hand_from_joint.linear() = hand.bind_joint_axes(j);
    hand_from_joint.translation() = hand.bind_joint_positions()[j];
    joint_from_hand[j] = hand_from_joint.inverse();
  }
  // The thumb's base (its CMC keypoint, behind the thumb's pivot) is a node of its own,
  // fixed to the wrist's node: the wrist moves it as it moves the skin.
  tinygltf::Node thumb_base;
  thumb_base.name = kGltfThumbBaseNode;
  const Eigen::Vector3d base =
      rest[0].Matrix().inverse() * (hand.hand_from_mesh().inverse() * hand.bind_keypoints()[kThumbBaseKeypoint]);
  thumb_base.translation = {base.x(), base.y(), base.z()};
  gltf.nodes[nodes[0]].children.push_back(static_cast<int>(gltf.nodes.size()));
  gltf.nodes.push_back(thumb_base);
  const size_t count = motion.frames.size();
  std::vector<float> times(count);
  std::array<std::vector<float>, kNumJoints> translations, rotations;
  const Eigen::Matrix3d world_from_camera = WorldFromCamera();
  const Eigen::Affine3d unscale(Eigen::Scaling(1.0 / s));
  for (size_t f = 0; f < count; ++f) {
    const MotionFrame& frame = motion.frames[f];
    times[f] = static_cast<float>(f / motion.fps);
    const auto posed = hand.JointTransforms(frame.pose.angles);
    Eigen::Affine3d world_from_hand = Eigen::Affine3d::Identity();
    world_from_hand.linear() = s * world_from_camera * frame.pose.camera_from_hand;
    world_from_hand.translation() = world_from_camera * frame.wrist_camera;
    for (int j = 0; j < kNumJoints; ++j) {
      // The joint's skinning motion of the mesh, applied to its rest node: its node posed.
      const Eigen::Affine3d skinning = world_from_hand * (posed[j] * joint_from_hand[j]) * hand.hand_from_mesh();
      const Eigen::Affine3d local = unscale * skinning * rest[j].Matrix();
      Eigen::Quaterniond rotation(Eigen::Matrix3d(local.linear() * rest[j].scale.cwiseInverse().asDiagonal()));
      rotation.normalize();
      // Neighbouring keys on one side of the quaternion sphere, so that they blend the short way.
      std::vector<float>& r = rotations[j];
      if (f > 0 && rotation.coeffs().dot(Eigen::Vector4d(r[r.size() - 4], r[r.size() - 3], r[r.size() - 2], r.back())) < 0) {
        rotation.coeffs() = -rotation.coeffs();
      }
      for (int a = 0; a < 3; ++a) translations[j].push_back(static_cast<float>(local.translation()[a]));
      for (int a = 0; a < 4; ++a) r.push_back(static_cast<float>(rotation.coeffs()[a]));  // x, y, z, w
    }
  }
  const int input = AddAccessor(&gltf, times, TINYGLTF_TYPE_SCALAR, count);
  gltf.accessors[input].minValues = {times.front()};
  gltf.accessors[input].maxValues = {times.back()};
  tinygltf::Animation animation;
  animation.name = "nphand";
  for (int j = 0; j < kNumJoints; ++j) {
    AddChannel(&animation, nodes[j], "translation", input, AddAccessor(&gltf, translations[j], TINYGLTF_TYPE_VEC3, count));
    AddChannel(&animation, nodes[j], "rotation", input, AddAccessor(&gltf, rotations[j], TINYGLTF_TYPE_VEC4, count));
  }
  gltf.animations.push_back(animation);
  gltf.buffers[0].data.resize((gltf.buffers[0].data.size() + 3) / 4 * 4, 0);
  gltf.asset.copyright = kMeshCopyright;
  gltf.asset.generator = std::string("nphand ") + kVersion;

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  NPHAND_THROW_CHECK(writer.WriteGltfSceneToStream(&gltf, out, false, true), "glTF: the animated hand could not be encoded");
  const std::string bytes = out.str();
  return {bytes.begin(), bytes.end()};
}

void WriteGltfMotion(const HandModel& hand, std::span<const uint8_t> asset_glb, const Motion& motion,
                     const std::filesystem::path& path) {
  WriteFileAtomic(path, GltfMotionBytes(hand, asset_glb, motion));
}

GltfMotion ReadGltfMotion(std::span<const uint8_t> glb, const std::string& source) {
  const tinygltf::Model gltf = Parse(glb, source);
  const std::array<int, kNumJoints> nodes = JointNodes(gltf, source);
  const std::vector<int> parents = NodeParents(gltf, source);
  NPHAND_THROW_CHECK(!gltf.animations.empty(), source, ": no animation");
  const tinygltf::Animation& animation = gltf.animations[0];
  const auto named = std::find_if(gltf.nodes.begin(), gltf.nodes.end(),
                                  [](const tinygltf::Node& node) { return node.name == kGltfThumbBaseNode; });
  const int thumb_base = named == gltf.nodes.end() ? -1 : static_cast<int>(named - gltf.nodes.begin());

  // Each animated node's keys, by path.
  size_t keys = 0;
  std::vector<float> times;
  std::map<std::pair<int, std::string>, std::vector<float>> values;
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    NPHAND_THROW_CHECK(channel.sampler >= 0 && channel.sampler < static_cast<int>(animation.samplers.size()), source,
                       ": an animation channel names a missing sampler");
    NPHAND_THROW_CHECK(channel.target_node >= 0 && channel.target_node < static_cast<int>(gltf.nodes.size()), source,
                       ": an animation channel names a missing node");
    const tinygltf::AnimationSampler& sampler = animation.samplers[channel.sampler];
    const std::vector<float> input =
        ReadAccessor<float>(gltf, sampler.input, TINYGLTF_COMPONENT_TYPE_FLOAT, 1, source, "animation times");
    NPHAND_THROW_CHECK(!input.empty() && (keys == 0 || input.size() == keys), source,
                       ": the animation's channels have different keys");
    keys = input.size();
    times = input;
    int components = 0;
    if (channel.target_path == "translation" || channel.target_path == "scale") components = 3;
    if (channel.target_path == "rotation") components = 4;
    if (components == 0) continue;  // morph weights: not a skeleton's
    std::vector<float> output =
        ReadAccessor<float>(gltf, sampler.output, TINYGLTF_COMPONENT_TYPE_FLOAT, components, source, "animation values");
    NPHAND_THROW_CHECK(output.size() == keys * components, source, ": an animation sampler has ", output.size() / components,
                       " values for ", keys, " keys");
    values[{channel.target_node, channel.target_path}] = std::move(output);
  }
  NPHAND_THROW_CHECK(keys > 0, source, ": the animation has no keys");

  GltfMotion motion;
  motion.joints = static_cast<int>(gltf.skins[0].joints.size());
  motion.copyright = gltf.asset.copyright;
  if (keys > 1 && times.back() > times.front()) motion.fps = (keys - 1) / (times.back() - times.front());
  std::vector<Trs> rest;
  for (const tinygltf::Node& node : gltf.nodes) rest.push_back(NodeTrs(node, source));
  for (size_t k = 0; k < keys; ++k) {
    std::vector<Eigen::Affine3d> local(gltf.nodes.size());
    for (size_t n = 0; n < gltf.nodes.size(); ++n) {
      Trs trs = rest[n];
      const int node = static_cast<int>(n);
      if (auto it = values.find({node, "translation"}); it != values.end()) {
        trs.translation = Eigen::Vector3f(&it->second[3 * k]).cast<double>();
      }
      if (auto it = values.find({node, "rotation"}); it != values.end()) {
        const float* q = &it->second[4 * k];
        trs.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
      }
      if (auto it = values.find({node, "scale"}); it != values.end()) {
        trs.scale = Eigen::Vector3f(&it->second[3 * k]).cast<double>();
      }
      local[n] = trs.Matrix();
    }
    auto position = [&](int node) {
      Eigen::Affine3d global = local[node];
      size_t depth = 0;
      for (int p = parents[node]; p >= 0; p = parents[p]) {
        NPHAND_THROW_CHECK(++depth <= gltf.nodes.size(), source, ": the node tree has a cycle");
        global = local[p] * global;
      }
      return Eigen::Vector3d(global.translation());
    };
    JointPositions positions;
    for (int j = 0; j < kNumJoints; ++j) positions[j] = position(nodes[j]);
    motion.frames.push_back(positions);
    if (thumb_base >= 0) motion.thumb_bases.push_back(position(thumb_base));
  }
  return motion;
}

Keypoints3d GltfKeypoints(const GltfMotion& motion, size_t frame) {
  NPHAND_CHECK(frame < motion.frames.size());
  const Eigen::Matrix3d camera_from_world = WorldFromCamera().transpose();
  NPHAND_THROW_CHECK(motion.thumb_bases.size() == motion.frames.size(), "glTF: no node '", kGltfThumbBaseNode,
                     "' (the thumb's CMC keypoint; not an nphand file, or one written before 2026-12-07)");
  Keypoints3d keypoints;
  for (int k = 0; k < kNumKeypoints; ++k) {
    keypoints[k] = camera_from_world * (k == kThumbBaseKeypoint ? motion.thumb_bases[frame]
                                                                : motion.frames[frame][Index(KeypointJoint(k))]);
  }
  return keypoints;
}

}  // namespace nphand
