#pragma once
/// \file html.h
/// A self-contained HTML page: pictures are embedded (PNG as data: URIs, SVG inline), so
/// the single file can be mailed, archived or opened anywhere.
#include <cstdint>
#include <string>
#include <vector>

namespace mrsnake::reports {

/// Escapes &, <, >, " and ' for HTML text and attributes.
std::string escape_html(const std::string& text);

class HtmlPage {
 public:
  explicit HtmlPage(std::string title);
  void heading(const std::string& text, int level = 2);
  void paragraph(const std::string& text);
  /// A highlighted note, e.g. why a picture is missing.
  void note(const std::string& text);
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
  /// Starts and ends a row of figures shown side by side.
  void begin_figures();
  void end_figures();
  void png(const std::vector<std::uint8_t>& bytes, const std::string& caption);
  void svg(const std::string& svg, const std::string& caption);
  std::string str() const;
  /// Writes the page atomically.
  /// \throw OutputError if it cannot be written.
  void save(const std::string& path) const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace mrsnake::reports
