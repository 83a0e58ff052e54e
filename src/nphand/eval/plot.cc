#include "nphand/eval/plot.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr int kWidth = 900, kHeight = 560, kLeft = 70, kRight = 210, kTop = 40, kBottom = 70;
const cv::Scalar kBlack(0, 0, 0);

const cv::Scalar& Colour(size_t i) {
  static const cv::Scalar palette[] = {{0, 0, 0},     {220, 60, 30}, {40, 160, 40}, {30, 30, 200}, {200, 150, 0},
                                       {160, 0, 160}, {0, 140, 220}, {90, 90, 90},  {0, 200, 200}, {120, 60, 0}};
  return palette[i % 10];
}

// A top for the y axis: the largest value rounded up to 1, 2 or 5 times a power of ten.
double NiceTop(double largest) {
  if (!(largest > 0.0)) return 1.0;
  const double power = std::pow(10.0, std::floor(std::log10(largest)));
  for (double step : {1.0, 2.0, 5.0, 10.0}) {
    if (step * power >= largest) return step * power;
  }
  return 10.0 * power;
}

void Text(cv::Mat* image, const std::string& text, cv::Point at, double scale = 0.45, const cv::Scalar& colour = kBlack) {
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

void Axes(cv::Mat* plot, const std::string& title, double top) {
  cv::line(*plot, {kLeft, kHeight - kBottom}, {kWidth - kRight, kHeight - kBottom}, kBlack);
  cv::line(*plot, {kLeft, kTop}, {kLeft, kHeight - kBottom}, kBlack);
  for (int t = 0; t <= 5; ++t) {
    const double v = top * t / 5;
    const int y = static_cast<int>(kHeight - kBottom - (kHeight - kTop - kBottom) * v / top);
    Text(plot, cv::format("%g", v), {8, y + 4});
  }
  Text(plot, title, {kLeft, 24}, 0.55);
}

}  // namespace

cv::Mat PlotLines(const std::vector<PlotSeries>& series, const std::string& title, const std::string& x_label) {
  double x_min = INFINITY, x_max = -INFINITY, y_max = 0.0;
  for (const PlotSeries& s : series) {
    NPHAND_THROW_CHECK(s.x.size() == s.y.size(), "plot: series '", s.name, "' has ", s.x.size(), " x and ", s.y.size(), " y");
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i]) || !std::isfinite(s.x[i])) continue;
      x_min = std::min(x_min, s.x[i]);
      x_max = std::max(x_max, s.x[i]);
      y_max = std::max(y_max, s.y[i]);
    }
  }
  if (!(x_max > x_min)) {
    x_min = std::isfinite(x_min) ? x_min - 0.5 : 0.0;
    x_max = x_min + 1.0;
  }
  const double top = NiceTop(y_max);
  cv::Mat plot(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  Axes(&plot, title, top);
  const auto x_of = [&](double x) { return kLeft + (kWidth - kLeft - kRight) * (x - x_min) / (x_max - x_min); };
  const auto y_of = [&](double y) { return kHeight - kBottom - (kHeight - kTop - kBottom) * y / top; };
  for (int t = 0; t <= 5; ++t) {
    const double x = x_min + (x_max - x_min) * t / 5;
    Text(&plot, cv::format("%g", x), {static_cast<int>(x_of(x)) - 8, kHeight - kBottom + 20});
  }
  Text(&plot, x_label, {kWidth / 2 - 80, kHeight - 20}, 0.55);
  for (size_t i = 0; i < series.size(); ++i) {
    std::vector<cv::Point> points;
    for (size_t j = 0; j < series[i].x.size(); ++j) {
      if (!std::isfinite(series[i].y[j]) || !std::isfinite(series[i].x[j])) continue;
      points.emplace_back(static_cast<int>(x_of(series[i].x[j])), static_cast<int>(y_of(series[i].y[j])));
    }
    cv::polylines(plot, points, false, Colour(i), 2, cv::LINE_AA);
    for (const cv::Point& p : points) cv::circle(plot, p, 3, Colour(i), cv::FILLED, cv::LINE_AA);
    Text(&plot, series[i].name, {kWidth - kRight + 15, kTop + 20 + 22 * static_cast<int>(i)}, 0.5, Colour(i));
  }
  return plot;
}

cv::Mat PlotBars(const std::vector<std::string>& names, const std::vector<double>& values, const std::string& title) {
  NPHAND_THROW_CHECK(names.size() == values.size() && !names.empty(), "plot: bars need one name per value");
  double y_max = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) y_max = std::max(y_max, v);
  }
  const double top = NiceTop(y_max);
  cv::Mat plot(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  Axes(&plot, title, top);
  const double slot = static_cast<double>(kWidth - kLeft - kRight) / names.size();
  for (size_t i = 0; i < names.size(); ++i) {
    const int x0 = static_cast<int>(kLeft + slot * i + slot * 0.15), x1 = static_cast<int>(kLeft + slot * (i + 0.85));
    if (std::isfinite(values[i])) {
      const int y = static_cast<int>(kHeight - kBottom - (kHeight - kTop - kBottom) * values[i] / top);
      cv::rectangle(plot, {x0, y}, {x1, kHeight - kBottom}, Colour(i), cv::FILLED);
      Text(&plot, cv::format("%.2f", values[i]), {x0, y - 6}, 0.4);
    }
    Text(&plot, names[i], {x0, kHeight - kBottom + 18 + 16 * static_cast<int>(i % 2)}, 0.4);
  }
  return plot;
}

}  // namespace nphand
