// Viewpoints: where the camera looks at the hand from.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nphand/util/random.h"

namespace nphand {

// A camera direction on the view sphere around the hand plus a roll about the viewing axis.
// Angles in radians. azimuth 0, elevation 0 looks at the palm; azimuth pi looks at the back
// of the hand; elevation pi/2 looks from the side the hand frame's +y points to.
struct Viewpoint {
  double azimuth = 0.0;
  double elevation = 0.0;
  double roll = 0.0;
};

// A viewpoint drawn uniformly: direction uniform on the sphere, roll uniform in [-pi, pi).
Viewpoint RandomViewpoint(Random& random);

// The unit direction from the hand towards the camera, in the hand frame.
Eigen::Vector3d ViewDirection(const Viewpoint& viewpoint);
// The viewpoint whose ViewDirection is `direction` (any non-zero vector), with `roll`.
Viewpoint ViewpointFromDirection(const Eigen::Vector3d& direction, double roll = 0.0);

// `count` directions spread uniformly over the sphere (the Fibonacci lattice: equal-area
// bands, golden-angle turns), deterministic. The paper samples 648.
std::vector<Eigen::Vector3d> ViewSphereDirections(int count);

struct ViewSphereCoverage {
  double max_neighbour_deg = 0.0;   // the largest angle from a direction to its nearest other one
  double covering_radius_deg = 0.0; // the largest angle from any point of the sphere to the
                                    // nearest direction (a spherical Voronoi vertex)

};
// O(n log n) with exact k-d tree searches (FLANN): the Voronoi vertices are sought among the
// circumcentres of each direction and two of its 8 nearest, which holds them for any
// evenly spread set such as the Fibonacci lattice.
ViewSphereCoverage MeasureCoverage(const std::vector<Eigen::Vector3d>& directions);

// camera_from_hand for a camera placed along ViewDirection and looking back at the hand,
// the fingers (hand +x) pointing up in the image at roll 0, then rolled about the optical
// axis by `roll` (positive turns the image content counter-clockwise).
Eigen::Matrix3d CameraFromHand(const Viewpoint& viewpoint);

// The wrist position in the camera frame that puts `centre_in_hand` on the optical axis at
// `distance` metres: wrist = (0, 0, distance) - camera_from_hand * centre_in_hand.
Eigen::Vector3d CenteredWristPosition(const Eigen::Matrix3d& camera_from_hand,
                                      const Eigen::Vector3d& centre_in_hand, double distance);

}  // namespace nphand
