#pragma once
/// \file canvas.h
/// A small RGB picture for slice overlays and plots that need no OpenGL, saved as PNG.
#include <cstdint>
#include <string>
#include <vector>

namespace mrsnake::reports {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

/// An 8-bit RGB image, row 0 at the top.
class Canvas {
 public:
  Canvas(int width, int height, Rgb background = {0, 0, 0});
  int width() const { return width_; }
  int height() const { return height_; }
  void set(int x, int y, Rgb c) {
    if (x >= 0 && y >= 0 && x < width_ && y < height_) pixels_[static_cast<std::size_t>(y) * width_ + x] = c;
  }
  Rgb get(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
  /// A line of the given thickness (in pixels) between two points in pixel coordinates.
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness = 1);
  /// PNG bytes of the picture (VTK's PNG writer, in memory).
  std::vector<std::uint8_t> png() const;

 private:
  int width_, height_;
  std::vector<Rgb> pixels_;
};

/// Standard base64 of bytes (for data: URIs in self-contained HTML pages).
std::string base64(const std::vector<std::uint8_t>& bytes);

}  // namespace mrsnake::reports
