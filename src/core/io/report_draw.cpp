// Drawing helpers of the PNG report.
#include "report_draw.h"

#include <cmath>
#include <sstream>

namespace camera_imu_alignment {
namespace report_draw {

int textWidth(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline).width;
}

std::string fitText(std::string text, int max_width, double scale) {
  if (textWidth(text, scale) <= max_width) return text;
  while (!text.empty() && textWidth(text + "...", scale) > max_width) text.pop_back();
  return text + "...";
}

std::vector<std::string> wrapText(const std::string& text, int max_width, double scale,
                                  int max_lines) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, current;
  while (words >> word) {
    const std::string candidate = current.empty() ? word : current + " " + word;
    if (current.empty() || textWidth(candidate, scale) <= max_width) {
      current = candidate;
      continue;
    }
    lines.push_back(current);
    current = word;
  }
  if (!current.empty()) lines.push_back(current);
  if (static_cast<int>(lines.size()) > max_lines) {
    lines.resize(max_lines);
    lines.back() += " ...";
  }
  for (std::string& line : lines) line = fitText(line, max_width, scale);
  return lines;
}

void putText(cv::Mat& img, const std::string& text, cv::Point origin, double scale,
             const cv::Scalar& colour, int max_width) {
  cv::putText(img, fitText(text, max_width, scale), origin, kFont, scale, colour, 1, cv::LINE_AA);
}

void panelFrame(cv::Mat& img, const cv::Rect& panel, const std::string& title) {
  cv::rectangle(img, panel, kGrey, 1);
  putText(img, title, panel.tl() + cv::Point(8, 20), 0.55, kBlack, panel.width - 16);
}

double niceCeil(double value) {
  const double p = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= value * (1.0 - 1e-12)) return m * p;
  }
  return 10.0 * p;
}

}  // namespace report_draw
}  // namespace camera_imu_alignment
