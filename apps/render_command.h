// `nphand render`: renders one posed hand (and optionally an object) from one viewpoint to
// PNG files: RGB, labels, depth, and the keypoints drawn on the RGB.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "nphand/model/hand_model.h"
#include "nphand/scene/grasp.h"

namespace nphand {

struct RenderCommandOptions {
  std::string hand = "right";            // right | left
  std::string pose = "relaxed";          // a named articulation (NamedArticulations())
  std::string grasp;                     // a grasp of the taxonomy ("large_diameter"), or "all"
  std::string gesture;                   // or a gesture ("peace"), or "all"
                                         // for a contact sheet; replaces pose and object
  int step = kGraspSteps - 1;            // which of the grasp's time steps (0: pre-shape)
  std::vector<std::string> angles;       // overrides "index_pip_flex=45" (degrees)
  double azimuth_deg = 0.0;              // viewpoint (scene/viewpoint.h); 0, 0 looks at the palm
  double elevation_deg = 0.0;
  double roll_deg = 0.0;
  double distance = 0.5;                 // camera to hand centre, metres
  int width = 512;                       // image size, pixels
  int height = 512;
  double fov_deg = 30.0;                 // horizontal field of view
  std::string object;                    // "" or a shape name (sphere, cylinder, box, disk, torus, stick)
  std::vector<double> object_size;       // metres, as ObjectSizeMeaning(shape)
  std::vector<double> object_at = {0.0, 0.0, 0.0};       // object centre in the hand frame, metres
  std::vector<double> object_rotate_deg = {0.0, 0.0, 0.0};  // about hand x, then y, then z
  std::string background;                // optional image file behind the scene
  std::filesystem::path out_dir = "out/render";
  std::string name = "hand";             // file name prefix
  std::filesystem::path asset_dir = DefaultAssetDir();

  bool Check(std::string* why) const;
};

struct RenderCommandResult {
  std::vector<std::filesystem::path> files;  // written: rgb, labels, depth, keypoints (or the sheet)
  int hand_pixels = 0;
  int object_pixels = 0;
};

RenderCommandResult RunRender(const RenderCommandOptions& options);

}  // namespace nphand
