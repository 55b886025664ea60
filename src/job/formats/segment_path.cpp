/// \file segment_path.cpp
/// \brief Reader of the "segment" scan-path format (adamantine, AdditiveFOAM) into a Job.
#include "scanhead/job/formats/segment_path.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kColumns = 6;
constexpr std::size_t kMinRowBytes = 12;  ///< "0 0 0 0 0 0\n": 6 one-character fields, 5 blanks, a newline

/// One line of the text: [begin, end) without the line break, and its 1-based number.
struct Line
{
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t number = 0;
};

/// Walks the text line by line ("\n" or "\r\n"); stops at the end.
class LineReader
{
public:
  explicit LineReader(const std::string& text)
    : text_(text)
  {
  }

  /// Next line that is not blank (spaces, tabs); false at the end.
  bool nextNonBlank(Line& line)
  {
    while (pos_ < text_.size())
    {
      line.begin = pos_;
      std::size_t nl = text_.find('\n', pos_);
      if (nl == std::string::npos)
        nl = text_.size();
      line.end = (nl > pos_ && text_[nl - 1] == '\r') ? nl - 1 : nl;
      line.number = ++number_;
      pos_ = nl + 1;
      for (std::size_t i = line.begin; i < line.end; ++i)
        if (text_[i] != ' ' && text_[i] != '\t')
          return true;
    }
    return false;
  }

  std::size_t position() const { return pos_ < text_.size() ? pos_ : text_.size(); }
  std::size_t lastLine() const { return number_; }

private:
  const std::string& text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

bool isBlank(char c)
{
  return c == ' ' || c == '\t';
}

std::string trimmed(const std::string& text, const Line& line)
{
  std::size_t b = line.begin;
  std::size_t e = line.end;
  while (b < e && isBlank(text[b]))
    ++b;
  while (e > b && isBlank(text[e - 1]))
    --e;
  return text.substr(b, e - b);
}

/// A non-negative decimal integer of at most 18 digits (an optional '+'), into \p value.
bool parseCount(const std::string& word, std::uint64_t& value)
{
  std::size_t i = (!word.empty() && word[0] == '+') ? 1 : 0;
  if (i == word.size() || word.size() - i > 18)
    return false;
  std::uint64_t v = 0;
  for (; i < word.size(); ++i)
  {
    if (word[i] < '0' || word[i] > '9')
      return false;
    v = 10 * v + static_cast<std::uint64_t>(word[i] - '0');
  }
  value = v;
  return true;
}

bool startsWithMode(const std::string& word)
{
  static const char kMode[] = "mode";
  if (word.size() < 4)
    return false;
  for (std::size_t i = 0; i < 4; ++i)
    if (std::tolower(static_cast<unsigned char>(word[i])) != kMode[i])
      return false;
  return word.size() == 4 || isBlank(word[4]);  // the word "Mode", not "Modes"
}

/// Shortened copy of a line for messages (a binary file may have huge "lines").
std::string excerpt(const std::string& word)
{
  std::string out = word.size() <= 40 ? word : word.substr(0, 40) + "...";
  for (char& c : out)
    if (!std::isprint(static_cast<unsigned char>(c)))
      c = '?';
  return out;
}

std::string stemOf(const std::string& source)
{
  const std::size_t slash = source.find_last_of("/\\");
  std::string name = slash == std::string::npos ? source : source.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0)
    name.resize(dot);
  return name.empty() ? "segment" : name;
}

const char* const kFieldNames[kColumns] = {"mode", "x", "y", "z", "power_coefficient", "param"};
const char* const kPowerFieldWatts = "power";  ///< column 5 in the AdditiveFOAM layout [W]

/// Number of blank-separated words of a text.
std::size_t wordCount(const std::string& text)
{
  std::size_t n = 0;
  for (std::size_t i = 0; i < text.size(); ++i)
    if (!isBlank(text[i]) && (i == 0 || isBlank(text[i - 1])))
      ++n;
  return n;
}

/// \brief Auto: what column 5 is by the column header's fifth word ("Mode x y z pmod param"): "pmod…" a coefficient,
/// "power…" W; otherwise Auto (the values decide).
SegmentPower columnFiveByHeader(const std::string& header)
{
  std::istringstream words(header);
  std::string word;
  for (int i = 0; i < 5 && words >> word; ++i)
  {
  }
  if (!words)
    return SegmentPower::Auto;
  for (char& c : word)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (word.compare(0, 4, "pmod") == 0)
    return SegmentPower::Coefficient;
  if (word.compare(0, 5, "power") == 0)
    return SegmentPower::Watts;
  return SegmentPower::Auto;
}

/// The parser's state: the job built so far, the current point, the polyline rows merge into.
class SegmentBuilder
{
public:
  /// \param power what column 5 is, Auto if the values must decide (finish())
  SegmentBuilder(const std::string& source, const SegmentReadOptions& options, SegmentPower power)
    : source_(source)
    , options_(options)
    , power_(power)
    , power_field_(power == SegmentPower::Coefficient ? kFieldNames[4] : kPowerFieldWatts)
  {
    job_.name = stemOf(source);
    job_.source = source;
    job_.file.begin(options.box_rotation_deg);
  }

  /// Parses one row (already known non-blank).
  void row(const std::string& text, const Line& line)
  {
    // Split into exactly kColumns words; parse each strictly.
    double value[kColumns] = {};
    std::size_t count = 0;
    std::size_t i = line.begin;
    while (true)
    {
      while (i < line.end && isBlank(text[i]))
        ++i;
      if (i >= line.end)
        break;
      std::size_t j = i;
      while (j < line.end && !isBlank(text[j]))
        ++j;
      if (count < kColumns)
      {
        word_.assign(text, i, j - i);
        const NumberText status = parseNumber(word_, value[count]);
        if (status != NumberText::Ok)
          fail(line, count == 4 ? power_field_ : kFieldNames[count],
               "'" + excerpt(word_) + "' is not a " + (status == NumberText::NotFinite ? "finite number" : "number"));
      }
      ++count;
      i = j;
    }
    if (count != kColumns)
      fail(line, "row",
           std::string("expected 6 columns (mode x y z ") + power_field_ + " param), got " + std::to_string(count));

    const double mode = value[0];
    if (mode != 0.0 && mode != 1.0)
      fail(line, "mode", shortestText(mode, 15) + " is not a known mode (expected 0: line, 1: spot)");
    const Eigen::Vector2d point(value[1] * options_.unit_m, value[2] * options_.unit_m);
    for (int axis = 0; axis < 2; ++axis)
      if (!std::isfinite(point[axis]))
        fail(line, kFieldNames[1 + axis],
             shortestText(value[1 + axis], 15) + " × unit " + shortestText(options_.unit_m, 15) +
                 " m is not a finite length");
    const double coefficient = value[4];
    if (!(coefficient >= 0.0))
      fail(line, power_field_, "must be >= 0 (got " + shortestText(coefficient, 15) + ")");
    const double param = value[5];
    ++rows_;
    if (rows_ > 1 && value[3] != z_)
      ++layer_;  // z changed: a new layer
    z_ = value[3];
    max_column5_ = std::max(max_column5_, coefficient);

    // Column 5 is kept as read; finish() scales it to W once the whole file has said what it is.
    const bool selected = options_.layer < 0 || layer_ == static_cast<std::size_t>(options_.layer);
    if (mode == 1.0)
      spot(line, point, coefficient, param, selected);
    else
      lineTo(line, point, coefficient, param, selected);
  }

  std::size_t rows() const { return rows_; }
  std::size_t layers() const { return rows_ == 0 ? 0 : layer_ + 1; }

  /// \brief The job, its powers in W: column 5 × the nominal power, or as read (see SegmentPower).
  Job finish()
  {
    const bool watts =
        power_ == SegmentPower::Watts || (power_ == SegmentPower::Auto && max_column5_ > kMaxCoefficient);
    const double scale_w = watts ? 1.0 : options_.power_w;
    for (Polyline& poly : job_.polylines)
      poly.power_w *= scale_w;
    job_.file.finish(layers());
    if (options_.layer >= 0 && layers() > 1)
      job_.name += "_layer" + std::to_string(options_.layer);  // as CLI names a selected layer
    return std::move(job_);
  }

  [[noreturn]] void fail(const Line& line, const std::string& field, const std::string& what) const
  {
    throw InputError(source_ + ":" + std::to_string(line.number) + ": " + field + ": " + what);
  }

private:
  void spot(const Line& line, const Eigen::Vector2d& point, double coefficient, double dwell_s, bool selected)
  {
    if (!(dwell_s >= 0.0))
      fail(line, "param", "a spot's dwell time must be >= 0 s (got " + shortestText(dwell_s, 15) + ")");
    merging_ = false;
    has_point_ = true;
    current_ = point;
    // The survey sees the polylines of the file read whole (cam.layer = -1).
    if (dwell_s > 0.0 && (coefficient > 0.0 || surveyed_any_))
    {
      job_.file.addPoint(point);
      job_.file.addTime(layer_, dwell_s);
      surveyed_any_ = true;
    }
    if (!(dwell_s > 0.0) || !selected)
      return;  // only goes there
    if (!(coefficient > 0.0) && job_.polylines.empty())
      return;  // a laser-off wait before anything: only shifts the time origin
    Polyline dwell;
    dwell.type = PolylineType::Mark;
    dwell.power_w = coefficient;
    dwell.dwell_s = dwell_s;
    dwell.points.push_back(point);
    job_.polylines.push_back(std::move(dwell));
  }

  void lineTo(const Line& line, const Eigen::Vector2d& point, double coefficient, double speed_mps, bool selected)
  {
    if (!has_point_)
      fail(line, "mode", "the first row must be a spot (mode 1): a line (mode 0) needs a start point");
    if (!(speed_mps > 0.0))
      fail(line, "param", "a line's speed must be > 0 m/s (got " + shortestText(speed_mps, 15) + ")");
    job_.file.addPoint(current_);
    job_.file.addPoint(point);
    job_.file.addTime(layer_, (point - current_).norm() / speed_mps);
    surveyed_any_ = true;
    if (!selected)
    {
      merging_ = false;
      current_ = point;
      return;
    }
    const PolylineType type = coefficient > 0.0 ? PolylineType::Mark : PolylineType::Jump;
    const double power_w = coefficient > 0.0 ? coefficient : 0.0;  // column 5 as read
    if (merging_)
    {
      Polyline& last = job_.polylines.back();
      if (last.type == type && last.speed_mps == speed_mps && last.power_w == power_w)
      {
        last.points.push_back(point);
        current_ = point;
        return;
      }
    }
    Polyline poly;
    poly.type = type;
    poly.speed_mps = speed_mps;
    poly.power_w = power_w;
    poly.points.push_back(current_);
    poly.points.push_back(point);
    job_.polylines.push_back(std::move(poly));
    merging_ = true;
    current_ = point;
  }

  const std::string& source_;
  const SegmentReadOptions& options_;
  static constexpr double kMaxCoefficient = 1.0;  ///< Auto: column 5 above this anywhere is in W
  const SegmentPower power_;
  const char* const power_field_;
  std::size_t layer_ = 0;  ///< layer of the current row
  double z_ = 0.0;         ///< z of the previous row
  double max_column5_ = 0.0;
  Job job_;
  std::string word_;
  Eigen::Vector2d current_ = Eigen::Vector2d::Zero();
  bool has_point_ = false;
  bool merging_ = false;       ///< the last polyline is a line the next mode-0 row may extend
  bool surveyed_any_ = false;  ///< the file read whole would have a polyline by now
  std::size_t rows_ = 0;
};
}  // namespace

void SegmentReadOptions::validate() const
{
  requireSetting(unit_m > 0.0 && std::isfinite(unit_m), "segment.unit_m", "> 0", unit_m);
  requireSetting(power_w >= 0.0 && std::isfinite(power_w), "segment.power_w", ">= 0", power_w);
}

Job parseSegmentPath(const std::string& text, const std::string& source, const SegmentReadOptions& options)
{
  options.validate();
  LineReader reader(text);
  auto fail = [&source](const Line& at, const std::string& field, const std::string& what) {
    throw InputError(source + ":" + std::to_string(at.number) + ": " + field + ": " + what);
  };
  const std::string header_help =
      "expected the header: a title line, the number of segments, then 'Mode x y z pmod param' (adamantine), "
      "or only 'Mode x y z power param' (AdditiveFOAM)";

  // Header: [title], count, "Mode ..." (adamantine) or only "Mode ..." (AdditiveFOAM); blank
  // lines skipped.
  Line line;
  if (!reader.nextNonBlank(line))
    throw InputError(source + ":" + std::to_string(reader.lastLine() + 1) + ": header: the file is empty; " +
                     header_help);
  std::string word = trimmed(text, line);
  const bool additive_foam = startsWithMode(word);
  // Auto: a header that names column 5 decides (adamantine's "pmod", AdditiveFOAM's "Power",
  // 3DThesis's "Pmod"); else the values do, in finish(). The header line is found below for adamantine.
  SegmentPower power = options.power_column;
  if (power == SegmentPower::Auto && additive_foam)
    power = columnFiveByHeader(word);
  std::uint64_t count = 0;
  Line count_line = line;
  if (!additive_foam)
  {
    if (!parseCount(word, count))
    {
      // a title line; the count must follow
      if (!reader.nextNonBlank(line))
        fail(Line{0, 0, reader.lastLine() + 1}, "count", "missing; " + header_help);
      word = trimmed(text, line);
      if (!parseCount(word, count))
        fail(line, "count",
             "'" + excerpt(word) + "' is not a number of segments (a non-negative integer); " + header_help);
    }
    count_line = line;
    if (!reader.nextNonBlank(line))
      fail(Line{0, 0, reader.lastLine() + 1}, "header", "missing the column header 'Mode x y z pmod param'");
    word = trimmed(text, line);
    if (!startsWithMode(word))
      fail(line, "header", "'" + excerpt(word) + "' is not the column header 'Mode x y z pmod param'");
    if (power == SegmentPower::Auto)
      power = columnFiveByHeader(word);

    // The count may not exceed what the rest of the file can hold; never used to reserve.
    const std::size_t rest = text.size() - reader.position();
    const std::uint64_t max_rows = (static_cast<std::uint64_t>(rest) + 1) / kMinRowBytes;
    if (count > max_rows)
      fail(count_line, "count",
           std::to_string(count) + " segments cannot fit in the " + std::to_string(rest) +
               " bytes that follow the header (at most " + std::to_string(max_rows) + " rows)");
  }

  SegmentBuilder builder(source, options, power);
  while (reader.nextNonBlank(line))
    builder.row(text, line);
  if (builder.rows() == 0)
    builder.fail(Line{0, 0, reader.lastLine() + 1}, "row", "no segment row after the header");
  if (options.exact_count && !additive_foam && builder.rows() != count)
    builder.fail(count_line, "count",
                 "the header says " + std::to_string(count) + " segments but the file has " +
                     std::to_string(builder.rows()) + " rows");
  if (options.layer >= 0 && static_cast<std::size_t>(options.layer) >= builder.layers())
    throw InputError(source + ": cam.layer: the file has " + std::to_string(builder.layers()) +
                     " layer(s) (z changes between rows start a new one), no layer " + std::to_string(options.layer) +
                     " (layers count from 0; -1: all)");
  return builder.finish();
}

Job readSegmentFile(const std::string& path, const SegmentReadOptions& options)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open the segment scan-path file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseSegmentPath(text.str(), path, options);
}

bool looksLikeSegmentPath(const std::string& first_bytes)
{
  // The first three non-blank lines: (count, Mode), (title, count, Mode), or a 6-word Mode header.
  LineReader reader(first_bytes);
  std::string words[3];
  std::size_t n = 0;
  Line line;
  while (n < 3 && reader.nextNonBlank(line))
    words[n++] = trimmed(first_bytes, line);
  std::uint64_t count = 0;
  if (n >= 1 && startsWithMode(words[0]) && wordCount(words[0]) == kColumns)
    return true;  // AdditiveFOAM: only the column header
  if (n >= 2 && parseCount(words[0], count) && startsWithMode(words[1]))
    return true;
  return n >= 3 && parseCount(words[1], count) && startsWithMode(words[2]);
}
}  // namespace scanhead
