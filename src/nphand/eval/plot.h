// Plain plots for the study reports (PNG through OpenCV): lines over a shared x axis, and
// bars. Axes run from 0 (or the data's smallest x) to a rounded top; every series is
// labelled in a legend on the right.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nphand {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // the same length; non-finite y values are skipped
};

cv::Mat PlotLines(const std::vector<PlotSeries>& series, const std::string& title, const std::string& x_label);
// One bar per value, named beneath.
cv::Mat PlotBars(const std::vector<std::string>& names, const std::vector<double>& values, const std::string& title);

}  // namespace nphand
