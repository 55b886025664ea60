/// \file html_page.cpp
/// \brief Pieces of the static HTML reports (html_page.hpp).
#include "scanhead/report/html_page.hpp"

namespace scanhead
{
std::string htmlEscape(const std::string& text)
{
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (const char c : text)
    switch (c)
    {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  return out;
}

std::string base64Encode(const std::string& bytes)
{
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  auto byte = [&bytes](std::size_t k) { return static_cast<unsigned>(static_cast<unsigned char>(bytes[k])); };
  for (; i + 3 <= bytes.size(); i += 3)
  {
    const unsigned v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size())
  {
    const bool two = i + 1 < bytes.size();
    const unsigned v = byte(i) << 16 | (two ? byte(i + 1) << 8 : 0u);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                      std::size_t numeric_from, std::size_t numeric_to)
{
  std::string out = "<table>\n<thead><tr>";
  for (const std::string& cell : header)
    out += "<th>" + htmlEscape(cell) + "</th>";
  out += "</tr></thead>\n<tbody>\n";
  for (const auto& row : rows)
  {
    out += "<tr>";
    for (std::size_t k = 0; k < row.size(); ++k)
      out += (k >= numeric_from && k < numeric_to ? "<td class=\"n\">" : "<td>") + htmlEscape(row[k]) + "</td>";
    out += "</tr>\n";
  }
  return out + "</tbody>\n</table>\n";
}

std::string htmlPngFigure(const std::string& png_bytes, const std::string& caption, int min_width_px)
{
  std::string size;
  if (png_bytes.size() >= 24 && min_width_px > 0)
  {
    // IHDR (PNG §11.2.2): the width is the big-endian word at byte 16.
    int width = 0;
    for (int k = 16; k < 20; ++k)
      width = width << 8 | static_cast<unsigned char>(png_bytes[static_cast<std::size_t>(k)]);
    if (width > 0 && width < min_width_px)
      size = " style=\"width: " + std::to_string(width * ((min_width_px + width - 1) / width)) +
             "px; image-rendering: pixelated\"";
  }
  return "<figure><img alt=\"" + htmlEscape(caption) + "\"" + size + " src=\"data:image/png;base64," +
         base64Encode(png_bytes) + "\"><figcaption>" + htmlEscape(caption) + "</figcaption></figure>\n";
}

std::string htmlDetails(const std::string& summary, const std::string& text)
{
  return "<details><summary>" + htmlEscape(summary) + "</summary><pre>" + htmlEscape(text) + "</pre></details>\n";
}

std::string htmlPage(const std::string& title, const std::string& body_html)
{
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + htmlEscape(title) +
         "</title>\n<style>\n"
         "body { font-family: sans-serif; margin: 1.5em auto; max-width: 1200px; padding: 0 1em; color: #222; }\n"
         "h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 1.6em; }\n"
         "table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }\n"
         "th, td { border: 1px solid #ccc; padding: 0.2em 0.6em; } th { background: #eee; text-align: left; }\n"
         "td.n { text-align: right; font-variant-numeric: tabular-nums; }\n"
         "figure { display: inline-block; margin: 0.5em; vertical-align: top; }\n"
         "figure img { max-width: 100%; border: 1px solid #ddd; }\n"
         "figcaption { font-size: 0.85em; color: #555; max-width: 560px; }\n"
         "pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; font-size: 0.8em; }\n"
         ".warn { color: #a40; }\n"
         "</style>\n</head>\n<body>\n" +
         body_html +
         // What loaded, for a reader and for the headless-browser test (data-* on <body>).
         "<script>\nwindow.addEventListener('load', function () {\n"
         "  var images = document.images, loaded = 0;\n"
         "  for (var i = 0; i < images.length; ++i) if (images[i].complete && images[i].naturalWidth > 0) ++loaded;\n"
         "  var b = document.body;\n"
         "  b.setAttribute('data-images', images.length);\n"
         "  b.setAttribute('data-images-loaded', loaded);\n"
         "  b.setAttribute('data-tables', document.querySelectorAll('table tbody tr').length > 0 ?\n"
         "      document.getElementsByTagName('table').length : 0);\n"
         "});\n</script>\n</body>\n</html>\n";
}
}  // namespace scanhead
