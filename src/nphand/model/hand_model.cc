#include "nphand/model/hand_model.h"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <system_error>

#include <tiny_gltf.h>

#include "nphand/model/gltf_accessor.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {
namespace {

Eigen::Isometry3d MakeFrame(const Eigen::Matrix3d& axes, const Eigen::Vector3d& origin) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = axes;
  frame.translation() = origin;
  return frame;
}

// A right-handed frame whose x is `bone` and whose z is as close to `up` as possible.
Eigen::Matrix3d FrameFromBone(const Eigen::Vector3d& bone, const Eigen::Vector3d& up) {
  Eigen::Matrix3d axes;
  axes.col(0) = bone.normalized();
  axes.col(1) = up.cross(axes.col(0)).normalized();
  axes.col(2) = axes.col(0).cross(axes.col(1));
  return axes;
}

bool IsThumb(int joint) { return joint >= 1 && joint <= 4; }

}  // namespace

std::vector<std::filesystem::path> AssetSearchDirs() {
  // The file holding this code (the program, or a shared object such as the Python module)
  // and the running program.
  std::vector<std::filesystem::path> binaries;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&AssetSearchDirs), &info) != 0 && info.dli_fname != nullptr &&
      info.dli_fname[0] == '/') {
    binaries.emplace_back(info.dli_fname);
  }
  std::error_code error;
  if (const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error); !error) {
    binaries.push_back(self);
  }
  std::vector<std::filesystem::path> dirs;
  const auto add = [&dirs](const std::filesystem::path& dir) {
    if (std::find(dirs.begin(), dirs.end(), dir) == dirs.end()) dirs.push_back(dir);
  };
  for (const std::filesystem::path& binary : binaries) {
    std::filesystem::path folder = binary.parent_path();
    for (int level = 0; level < 5 && !folder.empty(); ++level) {
      add(folder / "share" / "nphand" / "hand");
      if (folder == folder.root_path()) break;
      folder = folder.parent_path();
    }
  }
  add(NPHAND_INSTALL_ASSET_DIR);
  return dirs;
}

std::filesystem::path DefaultAssetDir() {
  if (const char* env = std::getenv("NPHAND_ASSET_DIR"); env != nullptr && *env != '\0') return env;
  const std::vector<std::filesystem::path> dirs = AssetSearchDirs();
  for (const std::filesystem::path& dir : dirs) {
    std::error_code error;
    if (std::filesystem::exists(dir / AssetFileName(Handedness::kRight), error)) return dir;
  }
  return dirs.empty() ? std::filesystem::path("share/nphand/hand") : dirs.front();
}

const char* PinnedAssetSha256(Handedness handedness) {
  return handedness == Handedness::kRight ? "291790c14f7f88a7f9bd35330c47392ed8e8d395ae6728f4bb7089f1bc1f2b96"
                                          : "bc67783144944ea1cda54d9247885825ea5fb9d4651469fe7d00be517a5c2b87";
}

std::string AssetFileName(Handedness handedness) { return ToString(handedness) + ".glb"; }

double HandLength(const Keypoints3d& k) {
  return (k[9] - k[0]).norm() + (k[10] - k[9]).norm() + (k[11] - k[10]).norm() + (k[12] - k[11]).norm();
}

std::array<bool, 4> FingerStates(const Keypoints3d& k) {
  constexpr double kStraightRatio = 0.75;
  std::array<bool, 4> straight{};
  for (int f = 0; f < 4; ++f) {
    const int m = 5 + 4 * f, p = m + 1, d = m + 2, t = m + 3;  // MCP, PIP, DIP, tip
    const double bones = (k[m] - k[p]).norm() + (k[p] - k[d]).norm() + (k[d] - k[t]).norm();
    straight[f] = bones > 0.0 && (k[m] - k[t]).norm() / bones > kStraightRatio;
  }
  return straight;
}

HandModel HandModel::Load(Handedness handedness, const std::filesystem::path& asset_dir) {
  const std::filesystem::path path = asset_dir / AssetFileName(handedness);
  NPHAND_THROW_CHECK(std::filesystem::exists(path), path.string(),
                     ": hand mesh not found (run scripts/setup.sh, install nphand, pass the asset folder or set "
                     "NPHAND_ASSET_DIR)");
  const std::vector<uint8_t> bytes = ReadFileBytes(path);
  const std::string sha = Sha256Hex(bytes);
  NPHAND_THROW_CHECK(sha == PinnedAssetSha256(handedness), path.string(), ": sha256 ", sha,
                     " differs from the pinned ", PinnedAssetSha256(handedness),
                     " (re-run scripts/setup.sh to fetch @webxr-input-profiles/assets@1.0.20)");
  return FromGlb(bytes, handedness, path.string());
}

HandModel HandModel::FromGlb(std::span<const uint8_t> glb, Handedness handedness, const std::string& source) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model gltf;
  std::string error, warning;
  const bool ok = loader.LoadBinaryFromMemory(&gltf, &error, &warning, glb.data(),
                                              static_cast<unsigned int>(glb.size()));
  NPHAND_THROW_CHECK(ok, source, ": not a readable binary glTF (", error, ")");
  NPHAND_THROW_CHECK(gltf.skins.size() == 1, source, ": expected one skin, found ", gltf.skins.size());
  const tinygltf::Skin& skin = gltf.skins[0];
  NPHAND_THROW_CHECK(skin.joints.size() == kNumJoints, source, ": expected ", kNumJoints,
                     " joints, found ", skin.joints.size());

  // Map the skin's joint slots to our joint order by name.
  std::array<int, kNumJoints> slot_to_joint{};
  for (int slot = 0; slot < kNumJoints; ++slot) {
    NPHAND_THROW_CHECK(skin.joints[slot] >= 0 && skin.joints[slot] < static_cast<int>(gltf.nodes.size()), source,
                       ": skin joint ", slot, " names a missing node");
    const std::string& name = gltf.nodes[skin.joints[slot]].name;
    int joint = -1;
    for (int j = 0; j < kNumJoints; ++j) {
      if (name == JointName(static_cast<Joint>(j))) joint = j;
    }
    NPHAND_THROW_CHECK(joint >= 0, source, ": unexpected joint '", name, "'");
    slot_to_joint[slot] = joint;
  }

  // Bind-pose joint positions in mesh coordinates: translations of the inverse bind matrices.
  const std::vector<float> ibm = ReadAccessor<float>(gltf, skin.inverseBindMatrices,
                                                     TINYGLTF_COMPONENT_TYPE_FLOAT, 16, source,
                                                     "inverse bind matrices");
  NPHAND_THROW_CHECK(ibm.size() == 16 * kNumJoints, source, ": wrong number of inverse bind matrices");
  JointPositions mesh_joints;
  for (int slot = 0; slot < kNumJoints; ++slot) {
    const Eigen::Map<const Eigen::Matrix4f> m(&ibm[16 * slot]);  // glTF is column-major
    mesh_joints[slot_to_joint[slot]] = m.inverse().block<3, 1>(0, 3).cast<double>();
  }

  // The hand frame in mesh coordinates.
  const double mirror = handedness == Handedness::kRight ? 1.0 : -1.0;
  const Eigen::Vector3d wrist = mesh_joints[Index(Joint::kWrist)];
  const Eigen::Vector3d forward = mesh_joints[Index(Joint::kMiddleProximal)] - wrist;
  const Eigen::Vector3d across = mesh_joints[Index(Joint::kIndexProximal)] - mesh_joints[Index(Joint::kLittleProximal)];
  const Eigen::Matrix3d hand_axes = FrameFromBone(forward, mirror * forward.cross(across));
  const Eigen::Isometry3d hand_from_mesh = MakeFrame(hand_axes, wrist).inverse();

  HandModel model;
  model.handedness_ = handedness;
  model.hand_from_mesh_ = hand_from_mesh;
  for (int j = 0; j < kNumJoints; ++j) model.bind_positions_[j] = hand_from_mesh * mesh_joints[j];

  model.SetJointFrames();

  // The skinned mesh: its one triangle primitive.
  const tinygltf::Primitive* primitive = nullptr;
  for (const tinygltf::Mesh& mesh : gltf.meshes) {
    for (const tinygltf::Primitive& p : mesh.primitives) {
      if (p.attributes.count("JOINTS_0") != 0) primitive = &p;
    }
  }
  NPHAND_THROW_CHECK(primitive != nullptr, source, ": no skinned mesh primitive");
  NPHAND_THROW_CHECK(primitive->mode == TINYGLTF_MODE_TRIANGLES, source, ": primitive is not a triangle list");
  auto attribute = [&](const char* name) {
    const auto it = primitive->attributes.find(name);
    NPHAND_THROW_CHECK(it != primitive->attributes.end(), source, ": mesh has no ", name);
    return it->second;
  };
  const std::vector<float> positions =
      ReadAccessor<float>(gltf, attribute("POSITION"), TINYGLTF_COMPONENT_TYPE_FLOAT, 3, source, "POSITION");
  const std::vector<float> normals =
      ReadAccessor<float>(gltf, attribute("NORMAL"), TINYGLTF_COMPONENT_TYPE_FLOAT, 3, source, "NORMAL");
  const std::vector<float> weights =
      ReadAccessor<float>(gltf, attribute("WEIGHTS_0"), TINYGLTF_COMPONENT_TYPE_FLOAT, 4, source, "WEIGHTS_0");
  const auto component_type = [&](int accessor, const char* what) {
    NPHAND_THROW_CHECK(accessor >= 0 && accessor < static_cast<int>(gltf.accessors.size()), source, ": ", what,
                       " accessor missing");
    return gltf.accessors[accessor].componentType;
  };
  const int joints_accessor = attribute("JOINTS_0");
  std::vector<uint16_t> joints;
  if (component_type(joints_accessor, "JOINTS_0") == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
    const std::vector<uint8_t> narrow = ReadAccessor<uint8_t>(
        gltf, joints_accessor, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, 4, source, "JOINTS_0");
    joints.assign(narrow.begin(), narrow.end());
  } else {
    joints = ReadAccessor<uint16_t>(gltf, joints_accessor, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, 4, source,
                                    "JOINTS_0");
  }
  const size_t n = positions.size() / 3;
  NPHAND_THROW_CHECK(n > 0 && normals.size() == 3 * n && weights.size() == 4 * n && joints.size() == 4 * n,
                     source, ": vertex attributes have different lengths");

  const Eigen::Matrix3f rotation = hand_from_mesh.linear().cast<float>();
  const Eigen::Vector3f translation = hand_from_mesh.translation().cast<float>();
  model.bind_vertices_.resize(n);
  model.bind_normals_.resize(n);
  model.skin_joints_.resize(n);
  model.skin_weights_.resize(n);
  for (size_t v = 0; v < n; ++v) {
    model.bind_vertices_[v] = rotation * Eigen::Vector3f(&positions[3 * v]) + translation;
    model.bind_normals_[v] = (rotation * Eigen::Vector3f(&normals[3 * v])).normalized();
    Eigen::Vector4f w(&weights[4 * v]);
    NPHAND_THROW_CHECK(w.minCoeff() >= 0.0f && w.sum() > 0.0f, source, ": vertex ", v, " has invalid skin weights");
    model.skin_weights_[v] = w / w.sum();
    for (int k = 0; k < 4; ++k) {
      const uint16_t slot = joints[4 * v + k];
      NPHAND_THROW_CHECK(slot < kNumJoints, source, ": vertex ", v, " names joint slot ", slot);
      model.skin_joints_[v][k] = static_cast<uint8_t>(slot_to_joint[slot]);
    }
  }

  std::vector<uint32_t> indices;
  if (component_type(primitive->indices, "indices") == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
    const std::vector<uint16_t> narrow = ReadAccessor<uint16_t>(
        gltf, primitive->indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, 1, source, "indices");
    indices.assign(narrow.begin(), narrow.end());
  } else {
    indices = ReadAccessor<uint32_t>(gltf, primitive->indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 1, source,
                                     "indices");
  }
  NPHAND_THROW_CHECK(indices.size() % 3 == 0, source, ": index count is not a multiple of 3");
  model.triangles_.resize(indices.size() / 3);
  for (size_t t = 0; t < model.triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      NPHAND_THROW_CHECK(indices[3 * t + k] < n, source, ": triangle ", t, " has an out-of-range index");
      model.triangles_[t][k] = static_cast<int>(indices[3 * t + k]);
    }
  }
  model.SetKeypoints();
  return model;
}

void HandModel::SetJointFrames() {
  // Anatomical joint frames: x along the bone to the child, z towards the back of the hand
  // (for the thumb: towards its nail, between the back of the hand and the radial side).
  const Eigen::Vector3d dorsal = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d ulnar =
      (bind_positions_[Index(Joint::kLittleProximal)] - bind_positions_[Index(Joint::kIndexProximal)]).normalized();
  bind_axes_[0] = Eigen::Matrix3d::Identity();
  for (int j = 1; j < kNumJoints; ++j) {
    if (IsTipJoint(j)) {
      bind_axes_[j] = bind_axes_[j - 1];
      continue;
    }
    const Eigen::Vector3d up = IsThumb(j) ? (dorsal - ulnar).normalized() : dorsal;
    bind_axes_[j] = FrameFromBone(bind_positions_[j + 1] - bind_positions_[j], up);
  }
  for (int j = 0; j < kNumJoints; ++j) {
    const Eigen::Isometry3d hand_from_joint = MakeFrame(bind_axes_[j], bind_positions_[j]);
    joint_from_hand_[j] = hand_from_joint.inverse();
    const int parent = JointParent(j);
    parent_from_joint_[j] = parent < 0 ? hand_from_joint : joint_from_hand_[parent] * hand_from_joint;
  }
}

HandModel HandModel::Reproportioned(double length, double width) const {
  NPHAND_THROW_CHECK(std::isfinite(length) && std::isfinite(width) && length >= 0.5 && length <= 2.0 && width >= 0.5 &&
                         width <= 2.0,
                     "hand proportions: length and width factors must be within [0.5, 2]");
  HandModel model = *this;
  const Eigen::Vector3d scale(length, width, width);
  for (Eigen::Vector3d& p : model.bind_positions_) p = p.cwiseProduct(scale);
  for (Eigen::Vector3f& v : model.bind_vertices_) v = v.cwiseProduct(scale.cast<float>());
  // Normals transform by the inverse transpose of the scaling.
  for (Eigen::Vector3f& n : model.bind_normals_) n = n.cwiseQuotient(scale.cast<float>()).normalized();
  model.SetJointFrames();
  model.SetKeypoints();
  return model;
}

void HandModel::SetKeypoints() {
  for (int k = 0; k < kNumKeypoints; ++k) {
    const int joint = Index(KeypointJoint(k));
    bind_keypoints_[k] = bind_positions_[joint];
    if (!IsTipJoint(joint) && k != kThumbBaseKeypoint) continue;
    // A fingertip goes forward along its last bone to the farthest skin that bone moves; the
    // thumb's base goes back along its metacarpal to the nearest skin the thumb moves.
    const int bone_joint = IsTipJoint(joint) ? joint - 1 : joint;
    const Eigen::Vector3d bone = (bind_positions_[bone_joint + 1] - bind_positions_[bone_joint]).normalized();
    const double way = IsTipJoint(joint) ? 1.0 : -1.0;
    double reach = 0.0;
    for (int v : VerticesMovedBy(bone_joint)) {
      reach = std::max(reach, way * (bind_vertices_[v].cast<double>() - bind_positions_[joint]).dot(bone));
    }
    bind_keypoints_[k] += way * reach * bone;
  }
}

Eigen::Vector3d HandModel::bind_centre() const {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : bind_positions_) centre += p;
  return centre / kNumJoints;
}

std::vector<int> HandModel::VerticesMovedBy(int joint, float min_weight) const {
  std::vector<int> vertices;
  for (size_t v = 0; v < skin_joints_.size(); ++v) {
    float weight = 0.0f;
    for (int k = 0; k < 4; ++k) {
      if (IsInSubtree(skin_joints_[v][k], joint)) weight += skin_weights_[v][k];
    }
    if (weight >= min_weight) vertices.push_back(static_cast<int>(v));
  }
  return vertices;
}

void HandModel::CheckHandedness(const HandPose& pose) const {
  NPHAND_THROW_CHECK(pose.handedness == handedness_, "a ", ToString(pose.handedness),
                     " hand pose was given to the ", ToString(handedness_), " hand model");
}

std::array<Eigen::Isometry3d, kNumJoints> HandModel::JointTransforms(const JointAngles& angles) const {
  // Abduction and roll turn about axes that mirroring reverses; flip them for the left hand
  // so that equal angles give mirror-image hands.
  const double mirror = handedness_ == Handedness::kRight ? 1.0 : -1.0;
  std::array<Eigen::Matrix3d, kNumJoints> local;
  local.fill(Eigen::Matrix3d::Identity());
  // Per joint, rotations compose as abduction * flexion * roll (abduction outermost).
  std::array<Eigen::Matrix3d, kNumJoints> abduction = local, flexion = local, roll = local;
  const auto& dofs = Dofs();
  for (int i = 0; i < kNumDofs; ++i) {
    const int j = Index(dofs[i].joint);
    switch (dofs[i].axis) {
      case DofAxis::kFlexion: flexion[j] = AxisAngle(Eigen::Vector3d::UnitY(), angles[i]); break;
      case DofAxis::kAbduction: abduction[j] = AxisAngle(Eigen::Vector3d::UnitZ(), mirror * angles[i]); break;
      case DofAxis::kRoll: roll[j] = AxisAngle(Eigen::Vector3d::UnitX(), mirror * angles[i]); break;
    }
  }
  std::array<Eigen::Isometry3d, kNumJoints> hand_from_joint;
  for (int j = 0; j < kNumJoints; ++j) {
    Eigen::Isometry3d rotation = Eigen::Isometry3d::Identity();
    rotation.linear() = abduction[j] * flexion[j] * roll[j];
    const int parent = JointParent(j);
    hand_from_joint[j] = (parent < 0 ? Eigen::Isometry3d::Identity() : hand_from_joint[parent]) *
                         parent_from_joint_[j] * rotation;
  }
  return hand_from_joint;
}

JointPositions HandModel::JointPositionsOf(const HandPose& pose) const {
  CheckHandedness(pose);
  const auto transforms = JointTransforms(pose.angles);
  JointPositions positions;
  for (int j = 0; j < kNumJoints; ++j) positions[j] = pose.camera_from_hand * transforms[j].translation();
  return positions;
}

Keypoints3d HandModel::KeypointsOf(const HandPose& pose) const {
  CheckHandedness(pose);
  const auto transforms = JointTransforms(pose.angles);
  Keypoints3d keypoints;
  for (int k = 0; k < kNumKeypoints; ++k) {
    const int joint = Index(KeypointJoint(k));
    // A fingertip moves with its tip joint, which moves with the last bone; the thumb's base
    // lies on the wrist's side of the thumb's pivot and moves with the wrist.
    const int frame = k == kThumbBaseKeypoint ? Index(Joint::kWrist) : joint;
    const Eigen::Vector3d in_hand =
        frame != joint || IsTipJoint(joint) ? Eigen::Vector3d(transforms[frame] * (joint_from_hand_[frame] * bind_keypoints_[k]))
                                            : transforms[joint].translation();
    keypoints[k] = pose.camera_from_hand * in_hand;
  }
  return keypoints;
}

void HandModel::Skin(const HandPose& pose, std::vector<Eigen::Vector3f>* vertices,
                     std::vector<Eigen::Vector3f>* normals) const {
  CheckHandedness(pose);
  const auto transforms = JointTransforms(pose.angles);
  std::array<Eigen::Matrix<float, 3, 4>, kNumJoints> skinning;
  for (int j = 0; j < kNumJoints; ++j) {
    Eigen::Isometry3d m = transforms[j] * joint_from_hand_[j];
    m.prerotate(pose.camera_from_hand);
    skinning[j] = m.matrix().topRows<3>().cast<float>();
  }
  const size_t n = bind_vertices_.size();
  vertices->resize(n);
  if (normals != nullptr) normals->resize(n);
  for (size_t v = 0; v < n; ++v) {
    const auto& joints = skin_joints_[v];
    const Eigen::Vector4f& w = skin_weights_[v];
    Eigen::Matrix<float, 3, 4> blend = w[0] * skinning[joints[0]];
    for (int k = 1; k < 4; ++k) {
      if (w[k] != 0.0f) blend += w[k] * skinning[joints[k]];
    }
    (*vertices)[v] = blend.leftCols<3>() * bind_vertices_[v] + blend.col(3);
    if (normals != nullptr) (*normals)[v] = (blend.leftCols<3>() * bind_normals_[v]).normalized();
  }
}

}  // namespace nphand
