#include "nphand/motion/bvh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {
namespace {

std::vector<int> ChildrenOf(int joint) {
  std::vector<int> children;
  for (int j = 0; j < kNumJoints; ++j) {
    if (JointParent(j) == joint) children.push_back(j);
  }
  return children;
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6f", std::abs(value) < 5e-7 ? 0.0 : value);
  return text;
}

std::string Vector(const Eigen::Vector3d& v) { return Number(v.x()) + " " + Number(v.y()) + " " + Number(v.z()); }

// Z, X, Y Euler angles in degrees of R = Rz(a) Rx(b) Ry(c), the channels' order, with b in
// [-90, 90] (and c = 0 where b is +-90): no rotation gives zeros.
Eigen::Vector3d ZxyDegrees(const Eigen::Matrix3d& r) {
  const double b = std::asin(std::clamp(r(2, 1), -1.0, 1.0));
  double a, c;
  if (std::abs(r(2, 1)) < 1.0 - 1e-12) {
    a = std::atan2(-r(0, 1), r(1, 1));
    c = std::atan2(-r(2, 0), r(2, 2));
  } else {
    a = std::atan2(r(1, 0), r(0, 0));
    c = 0.0;
  }
  return Eigen::Vector3d(a, b, c) * (180.0 / M_PI);
}

void WriteHierarchy(const HandModel& hand, double scale, int joint, int depth, std::ostringstream& out) {
  const std::string indent(2 * depth, ' ');
  const int parent = JointParent(joint);
  if (IsTipJoint(joint)) {
    // The end site is the fingertip keypoint: the finger's end, past the asset's tip joint.
    const Eigen::Vector3d tip =
        kBvhUnitsPerMetre * scale * (hand.bind_keypoints()[JointKeypoint(joint)] - hand.bind_joint_positions()[parent]);
    out << indent << "End Site\n" << indent << "{\n" << indent << "  OFFSET " << Vector(tip) << "\n" << indent << "}\n";
    return;
  }
  const Eigen::Vector3d offset =
      parent < 0 ? Eigen::Vector3d::Zero()
                 : Eigen::Vector3d(kBvhUnitsPerMetre * scale *
                                   (hand.bind_joint_positions()[joint] - hand.bind_joint_positions()[parent]));
  out << indent << (parent < 0 ? "ROOT " : "JOINT ") << JointName(static_cast<Joint>(joint)) << "\n" << indent << "{\n";
  out << indent << "  OFFSET " << Vector(offset) << "\n";
  out << indent << "  CHANNELS "
      << (parent < 0 ? "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" : "3 Zrotation Xrotation Yrotation")
      << "\n";
  if (parent < 0) {
    // The thumb's base (its CMC keypoint) is fixed to the wrist: a joint whose rotation
    // channels stay zero (readers that expect three per joint read it), whose end site is
    // the thumb's pivot.
    const int pivot = Index(Joint::kThumbMetacarpal);
    const Eigen::Vector3d base = hand.bind_keypoints()[kThumbBaseKeypoint];
    const std::string inner = indent + "  ";
    out << inner << "JOINT " << kBvhThumbBase << "\n" << inner << "{\n";
    out << inner << "  OFFSET " << Vector(kBvhUnitsPerMetre * scale * (base - hand.bind_joint_positions()[joint])) << "\n";
    out << inner << "  CHANNELS 3 Zrotation Xrotation Yrotation\n";
    out << inner << "  End Site\n" << inner << "  {\n" << inner << "    OFFSET "
        << Vector(kBvhUnitsPerMetre * scale * (hand.bind_joint_positions()[pivot] - base)) << "\n"
        << inner << "  }\n";
    out << inner << "}\n";
  }
  for (int child : ChildrenOf(joint)) WriteHierarchy(hand, scale, child, depth + 1, out);
  out << indent << "}\n";
}

// The joints with channels in the hierarchy's order (depth first, as written).
void ChannelJoints(int joint, std::vector<int>* order) {
  if (IsTipJoint(joint)) return;
  order->push_back(joint);
  for (int child : ChildrenOf(joint)) ChannelJoints(child, order);
}

Eigen::Matrix3d ChannelRotation(const std::string& channel, double degrees) {
  const double angle = degrees * M_PI / 180.0;
  if (channel == "Xrotation") return AxisAngle(Eigen::Vector3d::UnitX(), angle);
  if (channel == "Yrotation") return AxisAngle(Eigen::Vector3d::UnitY(), angle);
  return AxisAngle(Eigen::Vector3d::UnitZ(), angle);
}

}  // namespace

std::string BvhText(const HandModel& hand, const Motion& motion) {
  NPHAND_THROW_CHECK(hand.handedness() == motion.hand, "BVH: a ", ToString(motion.hand), " hand's motion was given the ",
                     ToString(hand.handedness()), " hand model");
  std::ostringstream out;
  out << "HIERARCHY\n";
  WriteHierarchy(hand, motion.scale, Index(Joint::kWrist), 0, out);
  std::vector<int> order;
  ChannelJoints(Index(Joint::kWrist), &order);
  out << "MOTION\nFrames: " << motion.frames.size() << "\nFrame Time: " << Number(1.0 / motion.fps) << "\n";
  const Eigen::Matrix3d world_from_camera = WorldFromCamera();
  for (const MotionFrame& frame : motion.frames) {
    const auto posed = hand.JointTransforms(frame.pose.angles);
    // Each joint's turn from its bind orientation, in the hand frame; a joint's channels
    // hold its turn relative to its parent's.
    std::array<Eigen::Matrix3d, kNumJoints> turn;
    for (int j = 0; j < kNumJoints; ++j) turn[j] = posed[j].linear() * hand.bind_joint_axes(j).transpose();
    for (int joint : order) {
      if (joint == Index(Joint::kWrist)) {
        out << Vector(kBvhUnitsPerMetre * (world_from_camera * frame.wrist_camera)) << " "
            << Vector(ZxyDegrees(world_from_camera * frame.pose.camera_from_hand * turn[joint])) << " 0 0 0";
      } else {
        out << " " << Vector(ZxyDegrees(turn[JointParent(joint)].transpose() * turn[joint]));
      }
    }
    out << "\n";
  }
  return out.str();
}

void WriteBvh(const HandModel& hand, const Motion& motion, const std::filesystem::path& path) {
  WriteFileAtomic(path, BvhText(hand, motion));
}

int Bvh::Find(const std::string& name) const {
  for (size_t j = 0; j < joints.size(); ++j) {
    if (joints[j].name == name) return static_cast<int>(j);
  }
  return -1;
}

std::vector<Eigen::Vector3d> Bvh::Positions(size_t frame) const {
  NPHAND_CHECK(frame < frames.size());
  const std::vector<double>& values = frames[frame];
  std::vector<Eigen::Matrix3d> rotation(joints.size());
  std::vector<Eigen::Vector3d> position(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    const BvhJoint& joint = joints[j];
    Eigen::Vector3d translation = joint.offset;
    Eigen::Matrix3d local = Eigen::Matrix3d::Identity();
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      const std::string& channel = joint.channels[c];
      const double value = values[joint.first_channel + c];
      if (channel == "Xposition") translation.x() += value;
      else if (channel == "Yposition") translation.y() += value;
      else if (channel == "Zposition") translation.z() += value;
      else local = local * ChannelRotation(channel, value);
    }
    if (joint.parent < 0) {
      position[j] = translation;
      rotation[j] = local;
    } else {
      position[j] = position[joint.parent] + rotation[joint.parent] * translation;
      rotation[j] = rotation[joint.parent] * local;
    }
  }
  return position;
}

Bvh ParseBvh(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  Bvh bvh;
  int line_number = 1;
  // Tokens with the line they are on.
  auto next = [&](std::string* token) {
    *token = "";
    char c;
    while (in.get(c)) {
      if (c == '\n') {
        if (!token->empty()) {
          in.unget();
          return true;
        }
        ++line_number;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        if (!token->empty()) return true;
      } else {
        token->push_back(c);
      }
    }
    return !token->empty();
  };
  auto fail = [&](const std::string& what) -> Error {
    return Error(source + ":" + std::to_string(line_number) + ": " + what);
  };
  auto expect = [&](const std::string& wanted) {
    std::string token;
    if (!next(&token) || token != wanted) throw fail("expected '" + wanted + "', found '" + token + "'");
  };
  auto number = [&](const char* what) {
    std::string token;
    if (!next(&token)) throw fail(std::string("the file ends where ") + what + " should be");
    try {
      size_t used = 0;
      const double value = std::stod(token, &used);
      if (used != token.size() || !std::isfinite(value)) throw std::invalid_argument(token);
      return value;
    } catch (const std::logic_error&) {
      throw fail(std::string("'") + token + "' is not a number (" + what + ")");
    }
  };

  expect("HIERARCHY");
  std::vector<int> open;  // the joints whose braces are open
  std::string token;
  bool body = false;
  while (next(&token)) {
    if (token == "MOTION") {
      body = true;
      break;
    }
    if (token == "ROOT" || token == "JOINT" || token == "End") {
      BvhJoint joint;
      joint.end_site = token == "End";
      if (token == "ROOT" && !open.empty()) throw fail("ROOT inside another joint");
      if (token != "ROOT" && open.empty()) throw fail(token + " outside any joint");
      joint.parent = open.empty() ? -1 : open.back();
      std::string name;
      if (!next(&name)) throw fail("a joint without a name");
      if (joint.end_site) {
        if (name != "Site") throw fail("expected 'End Site'");
        joint.name = bvh.joints[joint.parent].name + " end";
      } else {
        joint.name = name;
      }
      expect("{");
      expect("OFFSET");
      for (int a = 0; a < 3; ++a) joint.offset[a] = number("an offset");
      if (!joint.end_site) {
        expect("CHANNELS");
        const double count = number("a channel count");
        if (count < 0 || count > 6 || count != std::floor(count)) throw fail("a joint has 0 to 6 channels");
        joint.first_channel = bvh.channels;
        for (int c = 0; c < static_cast<int>(count); ++c) {
          std::string channel;
          if (!next(&channel)) throw fail("the file ends inside CHANNELS");
          if (channel != "Xposition" && channel != "Yposition" && channel != "Zposition" && channel != "Xrotation" &&
              channel != "Yrotation" && channel != "Zrotation") {
            throw fail("unknown channel '" + channel + "'");
          }
          joint.channels.push_back(channel);
        }
        bvh.channels += static_cast<int>(count);
      }
      bvh.joints.push_back(joint);
      open.push_back(static_cast<int>(bvh.joints.size()) - 1);
      if (joint.end_site) {
        expect("}");
        open.pop_back();
      }
    } else if (token == "}") {
      if (open.empty()) throw fail("a '}' closes nothing");
      open.pop_back();
    } else {
      throw fail("unexpected '" + token + "' in the hierarchy");
    }
  }
  if (!body) throw fail("no MOTION section");
  if (!open.empty()) throw fail("a joint's '{' is never closed");
  if (bvh.joints.empty()) throw fail("no joints");
  if (bvh.channels == 0) throw fail("no channels: the hierarchy holds no motion");
  expect("Frames:");
  const double frames = number("the frame count");
  if (frames < 0 || frames != std::floor(frames) || frames > 1e7) throw fail("an invalid frame count");
  expect("Frame");
  expect("Time:");
  bvh.frame_time_s = number("the frame time");
  if (!(bvh.frame_time_s > 0.0)) throw fail("the frame time must be positive");
  // Frames grow as their values are read: a false count costs nothing.
  for (double f = 0; f < frames; ++f) {
    std::vector<double> values(bvh.channels);
    for (double& value : values) value = number("a channel value");
    bvh.frames.push_back(std::move(values));
  }
  if (next(&token)) throw fail("more values than " + std::to_string(bvh.frames.size()) + " frames hold");
  return bvh;
}

Bvh ReadBvh(const std::filesystem::path& path) {
  const std::vector<uint8_t> bytes = ReadFileBytes(path);
  return ParseBvh(std::string(bytes.begin(), bytes.end()), path.string());
}

Keypoints3d BvhKeypoints(const Bvh& bvh, size_t frame) {
  const std::vector<Eigen::Vector3d> positions = bvh.Positions(frame);
  const Eigen::Matrix3d camera_from_world = WorldFromCamera().transpose();
  Keypoints3d keypoints;
  for (int k = 0; k < kNumKeypoints; ++k) {
    const int joint = Index(KeypointJoint(k));
    const std::string name = k == kThumbBaseKeypoint ? std::string(kBvhThumbBase)
                             : IsTipJoint(joint)     ? std::string(JointName(static_cast<Joint>(joint - 1))) + " end"
                                                     : std::string(JointName(static_cast<Joint>(joint)));
    const int j = bvh.Find(name);
    NPHAND_THROW_CHECK(j >= 0, "BVH: no joint '", name, "' (",
                       k == kThumbBaseKeypoint ? "the thumb's CMC keypoint; not an nphand file, or one written before 2026-12-07"
                                               : "not a generic-hand skeleton",
                       ")");
    keypoints[k] = camera_from_world * positions[j] / kBvhUnitsPerMetre;
  }
  return keypoints;
}

}  // namespace nphand
