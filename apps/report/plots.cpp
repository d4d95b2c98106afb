#include "apps/report/plots.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "apps/report/html.h"

namespace mrsnake::reports {
namespace {

constexpr int kWidth = 420, kHeight = 260;
constexpr int kLeft = 56, kRight = 14, kTop = 28, kBottom = 44;
const char* kPalette[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};

std::string number(double v) {
  std::ostringstream s;
  // Whole numbers below a million (counts) in full: "5450" fits the margin, "5.45e+03" does not.
  if (std::abs(v) < 1e6 && v == std::round(v)) {
    s << static_cast<long long>(v);
  } else {
    s.precision(3);
    s << v;
  }
  return s.str();
}

/// The frame, title, axis labels and min/max ticks of a chart.
void frame(std::ostringstream& svg, const std::string& title, const std::string& x_label, const std::string& y_label,
           double x0, double x1, double y0, double y1) {
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='" << kHeight
      << "' font-family='sans-serif' font-size='11'>"
      << "<rect width='100%' height='100%' fill='white'/>"
      << "<text x='" << kWidth / 2 << "' y='16' text-anchor='middle' font-size='13'>" << escape_html(title) << "</text>"
      << "<rect x='" << kLeft << "' y='" << kTop << "' width='" << kWidth - kLeft - kRight << "' height='"
      << kHeight - kTop - kBottom << "' fill='none' stroke='#444'/>"
      << "<text x='" << (kLeft + kWidth - kRight) / 2 << "' y='" << kHeight - 8 << "' text-anchor='middle'>"
      << escape_html(x_label) << "</text>"
      << "<text transform='translate(13," << (kTop + kHeight - kBottom) / 2 << ") rotate(-90)' text-anchor='middle'>"
      << escape_html(y_label) << "</text>"
      << "<text x='" << kLeft << "' y='" << kHeight - kBottom + 14 << "' text-anchor='middle'>" << number(x0)
      << "</text>"
      << "<text x='" << kWidth - kRight << "' y='" << kHeight - kBottom + 14 << "' text-anchor='middle'>" << number(x1)
      << "</text>"
      << "<text x='" << kLeft - 4 << "' y='" << kHeight - kBottom << "' text-anchor='end'>" << number(y0) << "</text>"
      << "<text x='" << kLeft - 4 << "' y='" << kTop + 8 << "' text-anchor='end'>" << number(y1) << "</text>";
}

}  // namespace

std::string svg_histogram(const std::vector<double>& values, int bins, double lo, double hi, const std::string& title,
                          const std::string& x_label) {
  if (lo == hi && !values.empty()) {
    lo = *std::min_element(values.begin(), values.end());
    hi = *std::max_element(values.begin(), values.end());
  }
  if (hi <= lo) hi = lo + 1;
  bins = std::max(1, bins);
  std::vector<double> counts(bins, 0);
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    const int b = std::clamp(static_cast<int>((v - lo) / (hi - lo) * bins), 0, bins - 1);
    ++counts[b];
  }
  const double top = std::max(1.0, *std::max_element(counts.begin(), counts.end()));
  std::ostringstream svg;
  frame(svg, title, x_label, "count", lo, hi, 0, top);
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  for (int b = 0; b < bins; ++b) {
    const double h = counts[b] / top * plot_h;
    svg << "<rect x='" << kLeft + b * plot_w / bins << "' y='" << kTop + plot_h - h << "' width='"
        << std::max(0.5, plot_w / bins - 1) << "' height='" << h << "' fill='#4a7fb5'/>";
  }
  svg << "</svg>";
  return svg.str();
}

std::string svg_line_plot(const std::vector<Series>& series, const std::string& title, const std::string& x_label,
                          const std::string& y_label, bool log_y) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  const auto fy = [&](double y) { return log_y ? std::log10(std::max(y, 1e-300)) : y; };
  for (const auto& s : series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(fy(s.y[i]))) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, fy(s.y[i]));
      y1 = std::max(y1, fy(s.y[i]));
    }
  if (x0 > x1) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  std::ostringstream svg;
  frame(svg, title, x_label, log_y ? "log10 " + y_label : y_label, x0, x1, y0, y1);
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const char* colour = kPalette[k % 8];
    svg << "<polyline fill='none' stroke='" << colour << "' stroke-width='1.5' points='";
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(fy(s.y[i]))) continue;
      svg << kLeft + (s.x[i] - x0) / (x1 - x0) * plot_w << ',' << kTop + plot_h - (fy(s.y[i]) - y0) / (y1 - y0) * plot_h
          << ' ';
    }
    svg << "'/><text x='" << kWidth - kRight - 4 << "' y='" << kTop + 14 + 13 * k << "' text-anchor='end' fill='"
        << colour << "'>" << escape_html(s.name) << "</text>";
  }
  svg << "</svg>";
  return svg.str();
}

}  // namespace mrsnake::reports
