/// \file correction_table.cpp
/// \brief The NC's correction table (SPEC §2.2, THESIS §2.3.2.2): build, interpolate, save, load.
/// The interpolation schemes, their measured accuracy and the file format are documented in
/// correction_table.hpp (CorrectionTable, CorrectionTable::load).
#include "scanhead/optics/correction_table.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
const char* const kHeader = "# scanhead correction table v1";
const char* const kHeaderPrefix = "# scanhead correction table v";
const char* const kColumns[] = {"i",       "j",       "q_x_rad", "q_y_rad",    "dq_x_dx",
                                "dq_y_dx", "dq_x_dy", "dq_y_dy", "d2q_x_dxdy", "d2q_y_dxdy"};
constexpr int kColumnCount = 10;

/// Upper bound on nodes per axis (n² nodes of 64 bytes each: 2049² ≈ 270 MB).
constexpr int kMaxNodes = 2049;

/// Shortest node line of a table file: 10 one-character fields, 9 separators and the newline.
constexpr int kMinNodeLineBytes = 20;

/// Largest half field of a table file [m]: a ±1 m field is beyond any galvo scan head (the shipped
/// config's is ±175 mm); larger values are a corrupt file.
constexpr double kMaxHalfWidth_m = 1.0;

/// Points this far outside [−h, h]² [m] are still accepted (rounding of computed edge points);
/// they are evaluated on the border cell's patch.
constexpr double kEdgeTolerance_m = 1e-9;

[[noreturn]] void throwOutside(const Eigen::Vector2d& spot_m, double half_width_m)
{
  std::ostringstream msg;
  msg.precision(12);
  msg << "correction table: point (" << spot_m.x() * 1e3 << ", " << spot_m.y() * 1e3 << ") mm lies outside the table [-"
      << half_width_m * 1e3 << ", " << half_width_m * 1e3 << "]² mm";
  throw NumericalError(msg.str());
}

void checkShape(int nodes, double half_width_m)
{
  if (nodes < 2 || nodes > kMaxNodes)
  {
    throw ConfigError("correction table nodes must be in [2, " + std::to_string(kMaxNodes) + "] (got " +
                      std::to_string(nodes) + ")");
  }
  if (!(half_width_m > 0.0) || !std::isfinite(half_width_m))
  {
    throw ConfigError("correction table half_width_m must be > 0 (got " + fullPrecisionText(half_width_m) + ")");
  }
}

/// Derivative of f along one grid axis from its samples at stride \p stride: central inside,
/// second-order one-sided on the border (first-order when there are only two samples).
template <typename Get>
double gridDerivative(const Get& f, int k, int n, double inv_spacing)
{
  if (n == 2)
    return (f(1) - f(0)) * inv_spacing;
  if (k == 0)
    return (-3.0 * f(0) + 4.0 * f(1) - f(2)) * (0.5 * inv_spacing);
  if (k == n - 1)
    return (3.0 * f(n - 1) - 4.0 * f(n - 2) + f(n - 3)) * (0.5 * inv_spacing);
  return (f(k + 1) - f(k - 1)) * (0.5 * inv_spacing);
}
}  // namespace

TableInterpolation parseTableInterpolation(const std::string& text, const std::string& field)
{
  if (text == "bilinear")
    return TableInterpolation::Bilinear;
  if (text == "bicubic")
    return TableInterpolation::Bicubic;
  throw ConfigError(field + " must be bilinear or bicubic (got '" + text + "')");
}

void CorrectionTable::setShape(int nodes, double half_width_m)
{
  nodes_ = nodes;
  half_width_m_ = half_width_m;
  spacing_m_ = 2.0 * half_width_m / (nodes - 1);
  inv_spacing_ = 1.0 / spacing_m_;
  node_.assign(static_cast<std::size_t>(nodes) * static_cast<std::size_t>(nodes), Node{});
}

CorrectionTable CorrectionTable::build(const OpticalModel& optics, int nodes, double half_width_m)
{
  checkShape(nodes, half_width_m);
  CorrectionTable table;
  table.setShape(nodes, half_width_m);
  const int n = nodes;
  const double h = half_width_m;
  const double s = table.spacing_m_;

  // Angles and exact first derivatives, row by row, each node warm-started from its neighbour
  // (the previous node of the row, or the first node of the previous row).
  Eigen::Vector2d guess = Eigen::Vector2d::Zero();
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const Eigen::Vector2d x(-h + i * s, -h + j * s);
      Node& node = table.node_[table.index(i, j)];
      if (i == 0 && j > 0)
        guess = Eigen::Vector2d(table.node_[table.index(0, j - 1)].q);
      Eigen::Vector2d q;
      Eigen::Matrix2d dq_dx;
      try
      {
        q = optics.inverse(x, guess);
        const Eigen::Matrix2d jac = optics.jacobian(q);
        const double det = jac.determinant();
        if (!(std::abs(det) > 1e-12))
          throw NumericalError("singular Jacobian");
        dq_dx << jac(1, 1), -jac(0, 1), -jac(1, 0), jac(0, 0);
        dq_dx /= det;
      }
      catch (const NumericalError& e)
      {
        std::ostringstream msg;
        msg << "correction table node (" << i << ", " << j << ") at (" << x.x() * 1e3 << ", " << x.y() * 1e3
            << ") mm: " << e.what();
        throw NumericalError(msg.str());
      }
      guess = q;
      for (int c = 0; c < 2; ++c)
      {
        node.q[c] = q[c];
        node.q_x[c] = dq_dx(c, 0);
        node.q_y[c] = dq_dx(c, 1);
      }
    }
  }

  // Cross derivatives: mean of d(q_x)/dy and d(q_y)/dx, differenced over the grid.
  const double inv_s = table.inv_spacing_;
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      for (int c = 0; c < 2; ++c)
      {
        const double qx_y = gridDerivative([&](int k) { return table.node_[table.index(i, k)].q_x[c]; }, j, n, inv_s);
        const double qy_x = gridDerivative([&](int k) { return table.node_[table.index(k, j)].q_y[c]; }, i, n, inv_s);
        table.node_[table.index(i, j)].q_xy[c] = 0.5 * (qx_y + qy_x);
      }
    }
  }
  return table;
}

/// The cell of a point inside the table and the Hermite bicubic patch there (the scheme on
/// CorrectionTable); one routine for joints(), jointsAndInverseJacobian() and predictBlock(), so
/// that all three give the same bits.
struct CorrectionTable::Cell
{
  const Node* n00;
  const Node* n10;
  const Node* n01;
  const Node* n11;
  double u;
  double v;

  Cell(const CorrectionTable& t, double x, double y)
  {
    // Cell (i, j) and local coordinates (u, v) in [0, 1].
    const int last_cell = t.nodes_ - 2;
    const double tx = (x + t.half_width_m_) * t.inv_spacing_;
    const double ty = (y + t.half_width_m_) * t.inv_spacing_;
    int i = static_cast<int>(tx);
    int j = static_cast<int>(ty);
    i = i < 0 ? 0 : (i > last_cell ? last_cell : i);
    j = j < 0 ? 0 : (j > last_cell ? last_cell : j);
    u = tx - i;
    v = ty - j;
    n00 = &t.node_[t.index(i, j)];
    n10 = n00 + 1;
    n01 = &t.node_[t.index(i, j + 1)];
    n11 = n01 + 1;
  }

  void bilinearWeights(double& w00, double& w10, double& w01, double& w11) const
  {
    w00 = (1.0 - u) * (1.0 - v);
    w10 = u * (1.0 - v);
    w01 = (1.0 - u) * v;
    w11 = u * v;
  }

  void bicubic(double s, double out[2]) const
  {
    // Hermite basis: value weights phi, slope weights psi (already scaled by the spacing s).
    const double u2 = u * u;
    const double u3 = u2 * u;
    const double v2 = v * v;
    const double v3 = v2 * v;
    const double pu1 = 3.0 * u2 - 2.0 * u3;
    const double pu0 = 1.0 - pu1;
    const double su0 = (u - 2.0 * u2 + u3) * s;
    const double su1 = (u3 - u2) * s;
    const double pv1 = 3.0 * v2 - 2.0 * v3;
    const double pv0 = 1.0 - pv1;
    const double sv0 = (v - 2.0 * v2 + v3) * s;
    const double sv1 = (v3 - v2) * s;
    // Both joints at once, one per lane: the same operations per lane as a scalar loop over them.
    const Pair row0 =
        pu0 * (pv0 * pair(n00->q) + sv0 * pair(n00->q_y)) + su0 * (pv0 * pair(n00->q_x) + sv0 * pair(n00->q_xy)) +
        pu1 * (pv0 * pair(n10->q) + sv0 * pair(n10->q_y)) + su1 * (pv0 * pair(n10->q_x) + sv0 * pair(n10->q_xy));
    const Pair row1 =
        pu0 * (pv1 * pair(n01->q) + sv1 * pair(n01->q_y)) + su0 * (pv1 * pair(n01->q_x) + sv1 * pair(n01->q_xy)) +
        pu1 * (pv1 * pair(n11->q) + sv1 * pair(n11->q_y)) + su1 * (pv1 * pair(n11->q_x) + sv1 * pair(n11->q_xy));
    const Pair sum = row0 + row1;
    std::memcpy(out, &sum, sizeof sum);
  }

  /// Bilinear interpolation of the nodes' ∂q/∂x: dq_dx[row c][column a] = m[2c + a].
  void inverseJacobian(double m[4]) const
  {
    double w00, w10, w01, w11;
    bilinearWeights(w00, w10, w01, w11);
    const Pair column_x = w00 * pair(n00->q_x) + w10 * pair(n10->q_x) + w01 * pair(n01->q_x) + w11 * pair(n11->q_x);
    const Pair column_y = w00 * pair(n00->q_y) + w10 * pair(n10->q_y) + w01 * pair(n01->q_y) + w11 * pair(n11->q_y);
    m[0] = column_x[0];
    m[1] = column_y[0];
    m[2] = column_x[1];
    m[3] = column_y[1];
  }

  /// Two doubles as one SSE2 vector (GCC vector extension: lane-wise IEEE operations).
  typedef double Pair __attribute__((vector_size(16)));
  static Pair pair(const double (&a)[2])
  {
    Pair p;
    std::memcpy(&p, a, sizeof p);
    return p;
  }
};

Eigen::Vector2d CorrectionTable::joints(const Eigen::Vector2d& spot_m, TableInterpolation interpolation) const
{
  const double h = half_width_m_;
  const double limit = h + kEdgeTolerance_m;
  if (!(std::abs(spot_m.x()) <= limit && std::abs(spot_m.y()) <= limit))
    throwOutside(spot_m, h);
  const Cell cell(*this, spot_m.x(), spot_m.y());
  if (interpolation == TableInterpolation::Bilinear)
  {
    double w00, w10, w01, w11;
    cell.bilinearWeights(w00, w10, w01, w11);
    return Eigen::Vector2d(w00 * cell.n00->q[0] + w10 * cell.n10->q[0] + w01 * cell.n01->q[0] + w11 * cell.n11->q[0],
                           w00 * cell.n00->q[1] + w10 * cell.n10->q[1] + w01 * cell.n01->q[1] + w11 * cell.n11->q[1]);
  }
  double out[2];
  cell.bicubic(spacing_m_, out);
  return Eigen::Vector2d(out[0], out[1]);
}

bool CorrectionTable::jointsAndInverseJacobian(const Eigen::Vector2d& spot_m, Eigen::Vector2d& q,
                                               Eigen::Matrix2d& dq_dx) const
{
  const double h = half_width_m_;
  const double limit = h + kEdgeTolerance_m;
  if (!(std::abs(spot_m.x()) <= limit && std::abs(spot_m.y()) <= limit) || nodes_ < 2)
    return false;
  const Cell cell(*this, spot_m.x(), spot_m.y());
  double out[2];
  cell.bicubic(spacing_m_, out);
  q = Eigen::Vector2d(out[0], out[1]);
  double m[4];
  cell.inverseJacobian(m);
  dq_dx << m[0], m[1], m[2], m[3];
  return true;
}

void CorrectionTable::predictBlock(std::size_t n, const double* x, const double* y, double* q_x, double* q_y,
                                   double* m00, double* m01, double* m10, double* m11, unsigned char* ok) const
{
  const double limit = half_width_m_ + kEdgeTolerance_m;
  for (std::size_t k = 0; k < n; ++k)
  {
    if (!(std::abs(x[k]) <= limit && std::abs(y[k]) <= limit) || nodes_ < 2)
    {
      q_x[k] = q_y[k] = 0.0;
      m00[k] = m01[k] = m10[k] = m11[k] = 0.0;
      ok[k] = 0;
      continue;
    }
    const Cell cell(*this, x[k], y[k]);
    double out[2];
    cell.bicubic(spacing_m_, out);
    double m[4];
    cell.inverseJacobian(m);
    q_x[k] = out[0];
    q_y[k] = out[1];
    m00[k] = m[0];
    m01[k] = m[1];
    m10[k] = m[2];
    m11[k] = m[3];
    ok[k] = 1;
  }
}

void CorrectionTable::save(const std::string& path) const
{
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out)
      throw InputError(tmp + ": cannot write the correction table");
    out << kHeader << "\n"
        << "# scanhead correction table: joint angles q = (q_x, q_y) [rad] at nodes x_i = -h + i*2h/(n-1),\n"
        << "# y_j likewise; derivatives of q w.r.t. the spot [rad/m, rad/m^2]; lines: j outer, i inner.\n"
        << "nodes " << nodes_ << "\n"
        << "half_width_m " << fullPrecisionText(half_width_m_) << "\n"
        << "columns";
    for (const char* c : kColumns)
      out << " " << c;
    out << "\n";
    for (int j = 0; j < nodes_; ++j)
    {
      for (int i = 0; i < nodes_; ++i)
      {
        const Node& node = node_[index(i, j)];
        out << i << " " << j;
        for (const double* pair : {node.q, node.q_x, node.q_y, node.q_xy})
          out << " " << fullPrecisionText(pair[0]) << " " << fullPrecisionText(pair[1]);
        out << "\n";
      }
    }
    out.flush();
    if (!out)
      throw InputError(tmp + ": write failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
  {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot rename " + tmp + " to it");
  }
}

CorrectionTable CorrectionTable::load(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open the correction table");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  return read(in, size > 0 ? static_cast<std::uint64_t>(size) : 0, path);
}

CorrectionTable CorrectionTable::parse(const std::string& text, const std::string& source)
{
  std::istringstream in(text);
  return read(in, text.size(), source);
}

CorrectionTable CorrectionTable::read(std::istream& in, std::uint64_t bytes, const std::string& path)
{
  int line_number = 0;
  auto fail = [&](const std::string& what) -> InputError {
    return InputError(path + ":" + std::to_string(line_number) + ": " + what);
  };

  std::string line;
  ++line_number;
  if (!std::getline(in, line))
    throw fail("empty file (expected '" + std::string(kHeader) + "')");
  if (!line.empty() && line.back() == '\r')
    line.pop_back();
  if (line != kHeader)
  {
    if (line.rfind(kHeaderPrefix, 0) == 0)
      throw fail("unsupported version 'v" + line.substr(std::string(kHeaderPrefix).size()) +
                 "' (this reader knows v1)");
    throw fail("not a correction table: the first line must be '" + std::string(kHeader) + "'");
  }

  CorrectionTable table;
  bool have_nodes = false, have_half_width = false, have_columns = false;
  int nodes = 0;
  double half_width_m = 0.0;
  std::size_t node_lines = 0;
  std::size_t expected_lines = 0;
  std::vector<std::string> tokens;
  while (std::getline(in, line))
  {
    ++line_number;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    tokens.clear();
    {
      std::istringstream fields(line);
      for (std::string t; fields >> t;)
        tokens.push_back(t);
    }
    if (tokens.empty() || tokens[0][0] == '#')
      continue;
    const char first = tokens[0][0];
    const bool is_key = (first >= 'a' && first <= 'z') || (first >= 'A' && first <= 'Z') || first == '_';
    if (is_key)
    {
      const std::string& key = tokens[0];
      if (node_lines > 0)
        throw fail("key '" + key + "' after the node lines (keys come first)");
      if (key == "columns")
      {
        if (have_columns)
          throw fail("duplicate key 'columns'");
        std::string expected;
        for (const char* c : kColumns)
          expected += std::string(expected.empty() ? "" : " ") + c;
        bool same = static_cast<int>(tokens.size()) == kColumnCount + 1;
        for (int k = 0; same && k < kColumnCount; ++k)
          same = tokens[k + 1] == kColumns[k];
        if (!same)
          throw fail("columns must be '" + expected + "'");
        have_columns = true;
        continue;
      }
      if (key != "nodes" && key != "half_width_m")
        throw fail("unknown key '" + key + "' (valid: nodes, half_width_m, columns)");
      if (tokens.size() != 2)
        throw fail("key '" + key + "' needs exactly one value (got " + std::to_string(tokens.size() - 1) + ")");
      if ((key == "nodes" && have_nodes) || (key == "half_width_m" && have_half_width))
        throw fail("duplicate key '" + key + "'");
      double value = 0.0;
      const NumberText parsed = parseNumber(tokens[1], value);
      if (parsed != NumberText::Ok)
        throw fail(key + " is " + (parsed == NumberText::NotFinite ? "not finite" : "not a number") + " ('" +
                   tokens[1] + "')");
      if (key == "nodes")
      {
        if (value != std::floor(value) || value < 2 || value > kMaxNodes)
          throw fail("nodes must be an integer in [2, " + std::to_string(kMaxNodes) + "] (got " + tokens[1] + ")");
        nodes = static_cast<int>(value);
        // Checked before the n² nodes are allocated: a node line has 10 fields, >= 20 bytes.
        const std::uint64_t need = static_cast<std::uint64_t>(nodes) * static_cast<std::uint64_t>(nodes) *
                                   static_cast<std::uint64_t>(kMinNodeLineBytes);
        if (need > bytes)
          throw fail("nodes " + tokens[1] + " needs " + std::to_string(nodes) + "² node lines (>= " +
                     std::to_string(need) + " bytes) but the file has " + std::to_string(bytes) + " bytes");
        have_nodes = true;
      }
      else
      {
        if (!(value > 0.0) || !(value <= kMaxHalfWidth_m))
          throw fail("half_width_m must be in (0, " + fullPrecisionText(kMaxHalfWidth_m) +
                     "] m (the table's half field; got " + tokens[1] + ")");
        half_width_m = value;
        have_half_width = true;
      }
      continue;
    }

    // A node line.
    if (node_lines == 0)
    {
      for (const auto& [present, key] : {std::pair<bool, const char*>{have_nodes, "nodes"},
                                         {have_half_width, "half_width_m"},
                                         {have_columns, "columns"}})
      {
        if (!present)
          throw fail(std::string("missing key '") + key + "' before the node lines");
      }
      table.setShape(nodes, half_width_m);
      expected_lines = static_cast<std::size_t>(nodes) * static_cast<std::size_t>(nodes);
    }
    if (node_lines >= expected_lines)
      throw fail("more node lines than nodes² = " + std::to_string(expected_lines));
    if (static_cast<int>(tokens.size()) != kColumnCount)
      throw fail("a node line needs " + std::to_string(kColumnCount) + " fields (got " + std::to_string(tokens.size()) +
                 ")");
    double values[kColumnCount];
    for (int k = 0; k < kColumnCount; ++k)
    {
      const NumberText parsed = parseNumber(tokens[k], values[k]);
      if (parsed != NumberText::Ok)
        throw fail(std::string("field '") + kColumns[k] + "' is " +
                   (parsed == NumberText::NotFinite ? "not finite" : "not a number") + " ('" + tokens[k] + "')");
    }
    const int want_i = static_cast<int>(node_lines % static_cast<std::size_t>(nodes));
    const int want_j = static_cast<int>(node_lines / static_cast<std::size_t>(nodes));
    if (values[0] != want_i || values[1] != want_j)
      throw fail("node indices (" + tokens[0] + ", " + tokens[1] + ") out of order: expected (" +
                 std::to_string(want_i) + ", " + std::to_string(want_j) + ")");
    Node& node = table.node_[node_lines];
    node.q[0] = values[2];
    node.q[1] = values[3];
    node.q_x[0] = values[4];
    node.q_x[1] = values[5];
    node.q_y[0] = values[6];
    node.q_y[1] = values[7];
    node.q_xy[0] = values[8];
    node.q_xy[1] = values[9];
    ++node_lines;
  }
  if (in.bad())
    throw fail("read error");
  if (node_lines == 0 || node_lines != expected_lines)
  {
    for (const auto& [present, key] : {std::pair<bool, const char*>{have_nodes, "nodes"},
                                       {have_half_width, "half_width_m"},
                                       {have_columns, "columns"}})
    {
      if (!present)
        throw fail(std::string("end of file: missing key '") + key + "'");
    }
    throw fail("end of file after " + std::to_string(node_lines) + " node lines, expected " + std::to_string(nodes) +
               " × " + std::to_string(nodes) + " = " +
               std::to_string(static_cast<std::size_t>(nodes) * static_cast<std::size_t>(nodes)));
  }
  return table;
}

TableErrorReport measureTableError(const CorrectionTable& table, TableInterpolation interpolation,
                                   const OpticalModel& optics, int probes_per_axis)
{
  if (probes_per_axis < 2)
    throw ConfigError("correction table probes_per_axis must be >= 2 (got " + std::to_string(probes_per_axis) + ")");
  const int p = probes_per_axis;
  const double h = table.halfWidth();
  const double step = 2.0 * h / (p - 1);
  TableErrorReport report;
  report.probes_per_axis = p;
  double sum_squares = 0.0;
  for (int j = 0; j < p; ++j)
  {
    for (int i = 0; i < p; ++i)
    {
      const Eigen::Vector2d x(-h + i * step, -h + j * step);
      const double e = (optics.spot(table.joints(x, interpolation)) - x).norm();
      sum_squares += e * e;
      if (e > report.max_error_m)
      {
        report.max_error_m = e;
        report.worst_point_m = x;
      }
    }
  }
  report.rms_error_m = std::sqrt(sum_squares / (static_cast<double>(p) * p));
  return report;
}
}  // namespace scanhead
