/// \file html_page.hpp
/// \brief Pieces of the project's static HTML reports (report.html of a results folder, summary.html of a study):
/// one self-contained file, its images embedded as data: URIs (RFC 2397, base64 of RFC 4648 §4), readable
/// offline and sendable as it is; no server, no network, no script library.
///
/// Every page carries a few lines of script that count, once the page has loaded, the images the browser
/// decoded and the tables it laid out, and write them on <body> (data-images, data-images-loaded,
/// data-tables): what the headless-browser test reads back.
#pragma once

#include <string>
#include <vector>

namespace scanhead
{
/// \brief \p text with &, <, >, " and ' as HTML character references.
std::string htmlEscape(const std::string& text);

/// \brief \p bytes in base64 (RFC 4648 §4, with padding).
std::string base64Encode(const std::string& bytes);

/// \brief A table: \p header cells, then \p rows (text, escaped here); the columns [\p numeric_from, \p numeric_to)
/// hold numbers (right-aligned, tabular figures).
std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                      std::size_t numeric_from = 1, std::size_t numeric_to = static_cast<std::size_t>(-1));

/// \brief A figure: the PNG \p png_bytes embedded, with \p caption under it; a picture narrower than \p min_width_px
/// is shown enlarged by a whole factor, its pixels kept square (a zoom at full resolution stays legible).
std::string htmlPngFigure(const std::string& png_bytes, const std::string& caption, int min_width_px = 0);

/// \brief A folded section holding \p text as preformatted text (a YAML file, a log).
std::string htmlDetails(const std::string& summary, const std::string& text);

/// \brief The whole page: <head> with \p title and the style sheet, \p body_html, the load check.
std::string htmlPage(const std::string& title, const std::string& body_html);
}  // namespace scanhead
