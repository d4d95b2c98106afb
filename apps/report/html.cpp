#include "apps/report/html.h"

#include "apps/report/canvas.h"
#include "mesh/atomic_file.h"

namespace mrsnake::reports {

std::string escape_html(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

HtmlPage::HtmlPage(std::string title) : title_(std::move(title)) {}

void HtmlPage::heading(const std::string& text, int level) {
  const std::string tag = "h" + std::to_string(level);
  body_ += "<" + tag + ">" + escape_html(text) + "</" + tag + ">\n";
}

void HtmlPage::paragraph(const std::string& text) { body_ += "<p>" + escape_html(text) + "</p>\n"; }

void HtmlPage::note(const std::string& text) { body_ += "<p class='note'>" + escape_html(text) + "</p>\n"; }

void HtmlPage::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table><tr>";
  for (const auto& h : header) body_ += "<th>" + escape_html(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& row : rows) {
    body_ += "<tr>";
    for (const auto& cell : row) body_ += "<td>" + escape_html(cell) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlPage::begin_figures() { body_ += "<div class='figures'>\n"; }
void HtmlPage::end_figures() { body_ += "</div>\n"; }

void HtmlPage::png(const std::vector<std::uint8_t>& bytes, const std::string& caption) {
  body_ += "<figure><img alt='" + escape_html(caption) + "' src='data:image/png;base64," + base64(bytes) +
           "'/><figcaption>" + escape_html(caption) + "</figcaption></figure>\n";
}

void HtmlPage::svg(const std::string& svg, const std::string& caption) {
  body_ += "<figure>" + svg + "<figcaption>" + escape_html(caption) + "</figcaption></figure>\n";
}

std::string HtmlPage::str() const {
  return "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>" + escape_html(title_) +
         "</title>\n<style>"
         "body{font-family:sans-serif;margin:2em;color:#222;max-width:1400px}"
         "table{border-collapse:collapse;margin:1em 0;font-size:13px}"
         "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}"
         "th{background:#eef2f7}td:first-child,th:first-child{text-align:left}"
         ".figures{display:flex;flex-wrap:wrap;gap:12px}"
         "figure{margin:0}figcaption{font-size:12px;color:#555;text-align:center}"
         ".note{background:#fff6d6;border-left:4px solid #e0b000;padding:6px 10px}"
         "</style></head><body>\n<h1>" +
         escape_html(title_) + "</h1>\n" + body_ + "</body></html>\n";
}

void HtmlPage::save(const std::string& path) const { write_text_file_atomically(path, str()); }

}  // namespace mrsnake::reports
