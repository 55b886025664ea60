/// \file cli_header.cpp
/// \brief The CLI header ($$HEADERSTART ... $$HEADEREND), common to ASCII and binary files.
#include <cmath>
#include <cstdio>

#include "cli_internal.hpp"
#include "cli_text.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace cli
{
std::string printable(const char* begin, const char* end, std::size_t max_chars)
{
  std::string out;
  for (const char* q = begin; q < end && out.size() < max_chars; ++q)
  {
    const unsigned char c = static_cast<unsigned char>(*q);
    if (c >= 0x20 && c < 0x7F)
      out += static_cast<char>(c);
    else
    {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    }
  }
  if (end - begin > static_cast<std::ptrdiff_t>(max_chars))
    out += "...";
  return out;
}

std::string TextCursor::token(std::size_t max_chars) const
{
  const char* q = p;
  while (q < end && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n' && *q != ',')
    ++q;
  if (q == p)
    return p < end ? printable(p, p + 1) : std::string("end of file");
  return printable(p, q, max_chars);
}

namespace
{
/// \brief The parameter text of a header command: after '/', up to the end of the line, a
/// comment or the next command; trailing blanks removed.
std::string_view parameterText(TextCursor& c)
{
  c.skipSpaces();
  if (c.atEnd() || *c.p != '/')
    return {};
  ++c.p;
  const char* start = c.p;
  while (!c.atEnd() && *c.p != '\n' && *c.p != '\r' && !c.startsWith("//") && !c.startsWith("$$"))
    ++c.p;
  const char* stop = c.p;
  while (stop > start && (stop[-1] == ' ' || stop[-1] == '\t'))
    --stop;
  return std::string_view(start, static_cast<std::size_t>(stop - start));
}

double headerNumber(std::string_view text, std::string_view command, const std::string& source, std::size_t line)
{
  double value = 0.0;
  const NumberText status = parseNumber(std::string(text), value);
  if (status != NumberText::Ok)
    failAtLine(source, line,
               "$$" + std::string(command) + ": expected a " + (status == NumberText::NotFinite ? "finite " : "") +
                   "number, got '" + printable(text.data(), text.data() + text.size()) + "'");
  return value;
}
}  // namespace

Header parseHeader(const std::string& bytes, const std::string& source)
{
  TextCursor c{bytes.data(), bytes.data() + bytes.size(), 1};
  if (c.startsWith("\xEF\xBB\xBF"))  // UTF-8 byte order mark
    c.p += 3;
  c.skipBlank();
  if (c.command() != "HEADERSTART")
    failAtLine(source, c.line, "expected $$HEADERSTART at the start of a CLI file");

  Header h;
  bool have_format = false;
  bool have_units = false;
  std::size_t layers_line = 0;
  std::string layers_text;
  for (;;)
  {
    c.skipBlank();
    if (c.atEnd())
      failAtLine(source, c.line, "file ends inside the header: expected $$HEADEREND");
    const std::size_t line = c.line;
    if (c.startsWith("$$HEADEREND"))
    {
      c.p += 11;  // binary geometry may follow at once: do not read further
      if (!have_format)
        failAtLine(source, line, "header has neither $$ASCII nor $$BINARY");
      if (!have_units)
        failAtLine(source, line, "header has no $$UNITS (mm per coordinate unit)");
      std::size_t offset = static_cast<std::size_t>(c.p - bytes.data());
      if (h.binary && h.aligned)
        offset = (offset + 3) / 4 * 4;
      h.geometry_offset = offset;
      h.geometry_line = line;
      // A layer takes at least 4 bytes of binary geometry (command 128 + z, 16 bit) or 9 of ASCII
      // ("$$LAYER/0"): a declared count the file cannot hold is a corrupt header, not a promise.
      // One more is allowed, so that a file cut right after its header still reads as empty.
      const std::size_t geometry_bytes = offset < bytes.size() ? bytes.size() - offset : 0;
      const std::size_t max_layers = 1 + geometry_bytes / (h.binary ? 4 : 9);
      if (h.declared_layers > 0 && static_cast<std::size_t>(h.declared_layers) > max_layers)
        failAtLine(source, layers_line,
                   "$$LAYERS/" + layers_text + " declares more layers than the file can hold (its " +
                       std::to_string(geometry_bytes) + " bytes of geometry hold at most " +
                       std::to_string(max_layers) + ")");
      return h;
    }
    const std::string_view name = c.command();
    if (name.empty())
      failAtLine(source, line, "expected a header command ($$NAME) or a // comment, got '" + c.token() + "'");
    const std::string_view param = parameterText(c);
    if (name == "ASCII" || name == "BINARY")
    {
      if (have_format && h.binary != (name == "BINARY"))
        failAtLine(source, line, "header has both $$ASCII and $$BINARY");
      h.binary = name == "BINARY";
      have_format = true;
    }
    else if (name == "UNITS")
    {
      const double u = headerNumber(param, name, source, line);
      if (!(u >= 1e-9) || !(u <= 1e3))
        failAtLine(source, line,
                   "$$UNITS: expected mm per coordinate unit in [1e-9, 1000], got '" +
                       printable(param.data(), param.data() + param.size()) + "'");
      h.units_mm = u;
      have_units = true;
    }
    else if (name == "LAYERS")
    {
      const double n = headerNumber(param, name, source, line);
      if (!(n >= 0.0) || n != std::floor(n) || n > 2e9)
        failAtLine(source, line,
                   "$$LAYERS: expected a layer count (integer >= 0), got '" +
                       printable(param.data(), param.data() + param.size()) + "'");
      h.declared_layers = static_cast<long>(n);
      layers_line = line;
      layers_text = printable(param.data(), param.data() + param.size());
    }
    else if (name == "VERSION")
      headerNumber(param, name, source, line);  // checked, not used
    else if (name == "ALIGN")
      h.aligned = true;
    else if (name == "HEADERSTART")
      failAtLine(source, line, "second $$HEADERSTART inside the header: expected $$HEADEREND");
    else if (name == "GEOMETRYSTART")
      failAtLine(source, line, "$$GEOMETRYSTART inside the header: expected $$HEADEREND first");
    // $$LABEL, $$DATE, $$DIMENSION, $$USERDATA and vendor commands: accepted, ignored.
  }
}
}  // namespace cli
}  // namespace scanhead
