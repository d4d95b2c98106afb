#pragma once
/// \file plots.h
/// Small SVG charts (histograms and line plots) for the HTML reports: vector pictures that
/// need no rendering library and stay crisp at any zoom.
#include <string>
#include <vector>

namespace mrsnake::reports {

/// A histogram of the values in `bins` equal bins over [lo, hi] (lo == hi: the data range).
std::string svg_histogram(const std::vector<double>& values, int bins, double lo, double hi, const std::string& title,
                          const std::string& x_label);

/// One named series of a line plot.
struct Series {
  std::string name;
  std::vector<double> x, y;
};

/// A line plot of several series on shared axes; log_y plots log10(y).
std::string svg_line_plot(const std::vector<Series>& series, const std::string& title, const std::string& x_label,
                          const std::string& y_label, bool log_y = false);

}  // namespace mrsnake::reports
