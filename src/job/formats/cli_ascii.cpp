/// \file cli_ascii.cpp
/// \brief ASCII CLI geometry ($$GEOMETRYSTART ... $$GEOMETRYEND) with the CLI+ lines.
#include <cmath>

#include "cli_internal.hpp"
#include "cli_text.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace cli
{
namespace
{
/// \brief Names one parameter for messages: "x of point 3 of 5" (k, n 1-based; 0 = none).
struct Field
{
  const char* name;
  std::size_t k = 0;
  std::size_t n = 0;
};

/// \brief An integral count as digits (up to 1e18), else in exponent form.
std::string countText(double n)
{
  return n >= 0.0 && n < 1e18 ? std::to_string(static_cast<long long>(n)) : toCharsText(n);
}

std::string describe(const Field& f)
{
  std::string s = f.name;
  if (f.n > 0)
    s += " " + std::to_string(f.k) + " of " + std::to_string(f.n);
  return s;
}

class AsciiGeometry
{
public:
  AsciiGeometry(const TextCursor& cursor, const std::string& source, JobBuilder& builder)
    : c_(cursor)
    , source_(source)
    , b_(builder)
  {
  }

  void run()
  {
    c_.skipBlank();
    if (c_.atEnd())
      return;  // header-only file: no layers
    if (c_.command() != "GEOMETRYSTART")
      failAtLine(source_, c_.line, "expected $$GEOMETRYSTART after $$HEADEREND");
    for (;;)
    {
      c_.skipBlank();
      if (c_.atEnd())
        failAtLine(source_, c_.line, "file ends inside the geometry section: expected $$GEOMETRYEND");
      const std::size_t line = c_.line;
      if (!c_.startsWith("$$"))
        failAtLine(source_, line, "expected a command ($$NAME), got '" + c_.token() + "'");
      const std::string_view cmd = c_.command();
      cmd_ = cmd;
      if (cmd == "LAYER")
      {
        beginParameters();
        number(Field{"z"});
        endParameters();
        b_.startLayer();
      }
      else if (cmd == "POLYLINE")
        polyline(line);
      else if (cmd == "HATCHES")
        hatches(line);
      else if (cmd == "POWER")
      {
        beginParameters();
        const double w = number(Field{"power [W]"});
        if (!(w >= 0.0))
          failAtLine(source_, line, "$$POWER: expected a power >= 0 W, got " + toCharsText(w));
        endParameters();
        b_.setPower(w);
      }
      else if (cmd == "SPEED")
      {
        beginParameters();
        const double v = number(Field{"speed [mm/s]"});
        if (!(v * 1e-3 > 0.0))  // also rejects denormals that vanish in m/s
          failAtLine(source_, line, "$$SPEED: expected a speed > 0 mm/s, got " + toCharsText(v));
        endParameters();
        b_.setSpeed(v * 1e-3);
      }
      else if (cmd == "FOCUS")
      {
        beginParameters();
        number(Field{"focus [mm]"});  // checked; ignored: the model has no focus axis
        endParameters();
      }
      else if (cmd == "GEOMETRYEND")
      {
        c_.skipBlank();
        if (!c_.atEnd())
          failAtLine(source_, c_.line, "expected the end of the file after $$GEOMETRYEND, got '" + c_.token() + "'");
        return;
      }
      else
        failAtLine(source_, line,
                   "unknown command '$$" + printable(cmd.data(), cmd.data() + cmd.size()) +
                       "' (expected $$LAYER, $$POLYLINE, $$HATCHES, $$POWER, $$SPEED, $$FOCUS or $$GEOMETRYEND)");
    }
  }

private:
  [[noreturn]] void fail(const std::string& what) const
  {
    failAtLine(source_, c_.line, "$$" + std::string(cmd_) + ": " + what);
  }

  void beginParameters()
  {
    c_.skipSpaces();
    if (c_.atEnd() || *c_.p != '/')
      fail("expected '/' and parameters, got '" + c_.token() + "'");
    ++c_.p;
    first_ = true;
  }

  double number(const Field& f)
  {
    c_.skipBlank();
    if (!first_ && !c_.atEnd() && *c_.p == ',')
    {
      ++c_.p;
      c_.skipBlank();
    }
    first_ = false;
    if (c_.atEnd() || c_.startsWith("$$"))
      fail("expected " + describe(f) + ", got " + (c_.atEnd() ? std::string("end of file") : "'" + c_.token() + "'"));
    double v = 0.0;
    bool overflow = false;
    const char* next = readNumber(c_.p, c_.end, v, overflow);
    if (overflow || (next != nullptr && isNumberEnd(next, c_.end) && !std::isfinite(v)))
      fail("expected a finite number for " + describe(f) + ", got '" + c_.token() + "'");
    if (next == nullptr || !isNumberEnd(next, c_.end))
      fail("expected a number for " + describe(f) + ", got '" + c_.token() + "'");
    if (!std::isfinite(v))
      fail("expected a finite number for " + describe(f) + ", got '" + c_.token() + "'");
    c_.p = next;
    return v;
  }

  double integer(const Field& f)
  {
    const double v = number(f);
    if (v != std::floor(v))
      fail("expected an integer for " + describe(f) + ", got " + toCharsText(v));
    return v;
  }

  /// \brief A count of items of \p numbers_per_item numbers each, checked against the bytes left
  /// (each number takes at least one character and one separator).
  std::size_t count(const Field& f, std::size_t numbers_per_item)
  {
    const double n = integer(f);
    if (n < 0.0)
      fail("expected " + describe(f) + " >= 0, got " + toCharsText(n));
    const double left = static_cast<double>(c_.remaining());
    if (2.0 * static_cast<double>(numbers_per_item) * n > left + 1.0)
      fail(describe(f) + " = " + countText(n) + " needs " + countText(n * static_cast<double>(numbers_per_item)) +
           " numbers, more than the remaining " + std::to_string(c_.remaining()) + " bytes can hold");
    return static_cast<std::size_t>(n);
  }

  void endParameters()
  {
    c_.skipBlank();
    if (!c_.atEnd() && *c_.p == ',')
    {
      ++c_.p;
      c_.skipBlank();
    }
    if (!c_.atEnd() && !c_.startsWith("$$"))
      fail("more parameters than expected: '" + c_.token() + "' (a count too small?)");
  }

  void requireLayer(std::size_t line) const
  {
    if (!b_.inLayer())
      failAtLine(source_, line, "$$" + std::string(cmd_) + " before any $$LAYER");
  }

  void polyline(std::size_t line)
  {
    requireLayer(line);
    beginParameters();
    integer(Field{"id"});
    const double dir = integer(Field{"dir"});
    if (dir < 0.0 || dir > 2.0)
      fail("expected dir 0 (clockwise), 1 (counter-clockwise) or 2 (open), got " + toCharsText(dir));
    const std::size_t n = count(Field{"point count n"}, 2);
    b_.beginMark(n, PolylineRole::Contour);
    for (std::size_t i = 1; i <= n; ++i)
    {
      const double x = number(Field{"x of point", i, n});
      const double y = number(Field{"y of point", i, n});
      b_.addPoint(x, y);
    }
    endParameters();
    b_.endMark();
  }

  void hatches(std::size_t line)
  {
    requireLayer(line);
    beginParameters();
    integer(Field{"id"});
    const std::size_t n = count(Field{"hatch count n"}, 4);
    for (std::size_t i = 1; i <= n; ++i)
    {
      const double xs = number(Field{"start x of hatch", i, n});
      const double ys = number(Field{"start y of hatch", i, n});
      const double xe = number(Field{"end x of hatch", i, n});
      const double ye = number(Field{"end y of hatch", i, n});
      b_.beginMark(2, PolylineRole::Hatch);
      b_.addPoint(xs, ys);
      b_.addPoint(xe, ye);
      b_.endMark();
    }
    endParameters();
  }

  TextCursor c_;
  const std::string& source_;
  JobBuilder& b_;
  std::string_view cmd_;
  bool first_ = true;
};
}  // namespace

void parseAsciiGeometry(const std::string& bytes, const Header& header, const std::string& source, JobBuilder& builder)
{
  TextCursor c{bytes.data() + header.geometry_offset, bytes.data() + bytes.size(), header.geometry_line};
  AsciiGeometry(c, source, builder).run();
}
}  // namespace cli
}  // namespace scanhead
