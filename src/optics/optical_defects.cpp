/// \file optical_defects.cpp
/// \brief The 30 assembly defects of the optical chain (SPEC §4, OPT §3): the OPT convention, its
/// mapping onto the defect joints of our URDF, defect set files, random sets, the defective URDF.
///
/// Element ↔ defect joint ↔ OpticalGeometry member (urdf/scanhead.urdf, optical_geometry_urdf.cpp):
///   source     → laser_source_defect_joint  → source    (beam along our +x)
///   axis_x     → galvo_x_mount_defect_joint → mount_x   (rotor axis our +z)
///   mirror_x   → mirror_x_defect_joint      → mirror_x  (in the rotor frame; our +x = surface normal)
///   axis_y, mirror_y → galvo_y_mount_defect_joint, mirror_y_defect_joint → mount_y, mirror_y
///   window_1, window_2 → window_*_defect_joint → window_1, window_2 (our +z = face normal)
///   work_plane → work_plane_defect_joint    → work_plane (spots in this frame)
/// Each member is the product of the URDF fixed-joint origins down to the defect link, the last
/// being `<element>_defect_joint` (identity in the nominal URDF), so right-multiplying it by D is
/// the same as writing D into that joint's origin (mount_* also carry the galvo joint origin after
/// the defect joint; it is identity in our URDF).
///
/// OPT (seeds/001_6db5768eacf0c62f.txt, "Tableau 1") lists per element only the components that
/// act on the spot, in its own frames: the beam along OPT x for the source, the rotation axis along
/// OPT x for the galvo axes (no x translation), the normal along OPT z for mirrors, windows and the
/// plane. Our frames put the rotation axis on z and the mirror normal on x, so each value goes to
/// the axis of our frame that plays the same role, by a cyclic relabelling of the axes (which keeps
/// rotations right-handed, so no sign changes):
///
/// | OPT component            | our defect joint          | our component      | sign |
/// |--------------------------|---------------------------|--------------------|------|
/// | source.y z               | laser_source              | x y z: y z         | +    |
/// | source.b c               | laser_source              | pitch yaw          | +    |
/// | axis_x.y z (⊥ axis)      | galvo_x_mount             | x y                | +    |
/// | axis_x.a (about axis)    | galvo_x_mount             | yaw (about z)      | +    |
/// | axis_x.b c (axis tilts)  | galvo_x_mount             | roll pitch         | +    |
/// | mirror_x.z (normal)      | mirror_x                  | x                  | +    |
/// | mirror_x.a b (tilts)     | mirror_x                  | pitch yaw          | +    |
/// | axis_y.*, mirror_y.*     | galvo_y_mount, mirror_y   | as axis_x, mirror_x| +    |
/// | window_k.a b (tilts)     | window_k                  | roll pitch         | +    |
/// | work_plane.x y z a b c   | work_plane                | x y z roll pitch yaw | +  |
///
/// i.e. galvo mounts: OPT (x, y, z) → our (z, x, y); mirrors: OPT (x, y, z) → our (y, z, x);
/// the others as written. Placed literally instead, a mirror's z translation and a rotation would
/// slide or spin the mirror in its own plane and do nothing. Values: mm → m and mrad → rad (÷ 1000).
/// The rotation is composed as the URDF does (D = Trans(t)·Rz(yaw)·Ry(pitch)·Rx(roll) about OUR
/// axes); for the galvo mounts this is OPT's extrinsic x-y-z order with the axes relabelled only
/// up to second order (≤ 1e-8 rad for 0.1 mrad defects, ~10 nm on the plane).
#include "scanhead/optics/optical_defects.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kElementCount = 8;

/// The YAML keys of the elements, in defectJointElements() order.
const char* const kElementKeys[kElementCount] = { "source",   "axis_x",   "mirror_x", "axis_y",
                                                  "mirror_y", "window_1", "window_2", "work_plane" };

/// One row of the mapping table (file comment): OPT component → our defect joint, axis, sign.
struct Mapping
{
  std::size_t element;  ///< index in kElementKeys / defectJointElements()
  char component;       ///< OPT: x y z a b c
  int our_axis;         ///< 0, 1, 2: x, y, z of the translation, or roll, pitch, yaw
  double sign;          ///< +1 (cyclic relabelling)
};

// clang-format off
const Mapping kMapping[kDefectCount] = {
  { 0, 'y', 1, 1.0 }, { 0, 'z', 2, 1.0 }, { 0, 'b', 1, 1.0 }, { 0, 'c', 2, 1.0 },                      // source
  { 1, 'y', 0, 1.0 }, { 1, 'z', 1, 1.0 }, { 1, 'a', 2, 1.0 }, { 1, 'b', 0, 1.0 }, { 1, 'c', 1, 1.0 },  // axis_x
  { 2, 'z', 0, 1.0 }, { 2, 'a', 1, 1.0 }, { 2, 'b', 2, 1.0 },                                          // mirror_x
  { 3, 'y', 0, 1.0 }, { 3, 'z', 1, 1.0 }, { 3, 'a', 2, 1.0 }, { 3, 'b', 0, 1.0 }, { 3, 'c', 1, 1.0 },  // axis_y
  { 4, 'z', 0, 1.0 }, { 4, 'a', 1, 1.0 }, { 4, 'b', 2, 1.0 },                                          // mirror_y
  { 5, 'a', 0, 1.0 }, { 5, 'b', 1, 1.0 },                                                              // window_1
  { 6, 'a', 0, 1.0 }, { 6, 'b', 1, 1.0 },                                                              // window_2
  { 7, 'x', 0, 1.0 }, { 7, 'y', 1, 1.0 }, { 7, 'z', 2, 1.0 },                                          // work_plane
  { 7, 'a', 0, 1.0 }, { 7, 'b', 1, 1.0 }, { 7, 'c', 2, 1.0 },
};
// clang-format on

bool isRotation(char component)
{
  return component == 'a' || component == 'b' || component == 'c';
}

/// The pose each element's defect applies to, in defectJointElements() order.
Eigen::Isometry3d& pose(OpticalGeometry& g, std::size_t element)
{
  Eigen::Isometry3d* const members[kElementCount] = { &g.source,   &g.mount_x,  &g.mirror_x, &g.mount_y,
                                                      &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane };
  return *members[element];
}

/// "z, a, b": the components OPT lists for \p element.
std::string allowedComponents(std::size_t element)
{
  std::string list;
  for (const Mapping& m : kMapping)
  {
    if (m.element == element)
      list += (list.empty() ? "" : ", ") + std::string(1, m.component);
  }
  return list;
}

std::string elementList()
{
  std::string list;
  for (const char* key : kElementKeys)
    list += (list.empty() ? "" : ", ") + std::string(key);
  return list;
}

/// Index in the 30 of (element, component), or kDefectCount.
std::size_t componentIndex(std::size_t element, const std::string& component)
{
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    if (kMapping[k].element == element && component.size() == 1 && component[0] == kMapping[k].component)
      return k;
  }
  return kDefectCount;
}

std::string where(const std::string& path, const YAML::Node& node)
{
  return path + ":" + std::to_string(node.Mark().line + 1);
}

std::string fileStem(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

/// Shortest "%.*g" text that reads back as exactly \p value (at most 17 digits).
std::string exactText(double value)
{
  char buffer[40];
  for (int digits = 1; digits <= 17; ++digits)
  {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value)
      break;
  }
  return buffer;
}

/// splitmix64 (Steele, Lea, Flood 2014; the seeding generator of xoshiro): fixed integer
/// arithmetic, so the same sequence on every platform.
std::uint64_t splitMix64(std::uint64_t& state)
{
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// ---- urdfWithDefects: plain text substitution outside XML comments --------------------------

class UrdfText
{
public:
  explicit UrdfText(const std::string& text) : text_(text)
  {
    for (std::size_t at = text.find("<!--"); at != std::string::npos; at = text.find("<!--", at))
    {
      const std::size_t end = text.find("-->", at + 4);
      const std::size_t stop = end == std::string::npos ? text.size() : end + 3;
      comments_.emplace_back(at, stop);
      at = stop;
    }
  }

  /// First occurrence of \p needle at or after \p from, before \p limit, outside comments.
  std::size_t find(const std::string& needle, std::size_t from, std::size_t limit = std::string::npos) const
  {
    for (std::size_t at = text_.find(needle, from); at != std::string::npos && at < limit;
         at = text_.find(needle, at + 1))
    {
      if (!inComment(at))
        return at;
    }
    return std::string::npos;
  }

  /// First tag `<name` (followed by a space, '/' or '>') in [from, limit).
  std::size_t findTag(const std::string& name, std::size_t from, std::size_t limit = std::string::npos) const
  {
    const std::string open = "<" + name;
    for (std::size_t at = find(open, from, limit); at != std::string::npos; at = find(open, at + 1, limit))
    {
      const std::size_t next = at + open.size();
      if (next < text_.size() && (std::isspace(static_cast<unsigned char>(text_[next])) || text_[next] == '/' ||
                                  text_[next] == '>'))
        return at;
    }
    return std::string::npos;
  }

  /// Value of attribute \p name in the tag [begin, end), or "" if absent.
  std::string attribute(std::size_t begin, std::size_t end, const std::string& name) const
  {
    const std::string tag = text_.substr(begin, end - begin);
    for (std::size_t at = tag.find(name); at != std::string::npos; at = tag.find(name, at + 1))
    {
      if (at == 0 || !std::isspace(static_cast<unsigned char>(tag[at - 1])))
        continue;
      std::size_t k = at + name.size();
      while (k < tag.size() && std::isspace(static_cast<unsigned char>(tag[k])))
        ++k;
      if (k >= tag.size() || tag[k] != '=')
        continue;
      ++k;
      while (k < tag.size() && std::isspace(static_cast<unsigned char>(tag[k])))
        ++k;
      if (k >= tag.size() || (tag[k] != '"' && tag[k] != '\''))
        continue;
      const std::size_t close = tag.find(tag[k], k + 1);
      if (close == std::string::npos)
        return "";
      return tag.substr(k + 1, close - k - 1);
    }
    return "";
  }

  const std::string& text() const { return text_; }

private:
  bool inComment(std::size_t at) const
  {
    for (const auto& c : comments_)
    {
      if (at >= c.first && at < c.second)
        return true;
    }
    return false;
  }

  const std::string& text_;
  std::vector<std::pair<std::size_t, std::size_t>> comments_;  ///< [begin, end) of each comment
};

std::string tripleText(const Eigen::Vector3d& v)
{
  return fullPrecisionText(v.x()) + " " + fullPrecisionText(v.y()) + " " + fullPrecisionText(v.z());
}
}  // namespace

const std::array<DefectComponent, kDefectCount>& defectComponents()
{
  static const std::array<DefectComponent, kDefectCount> components = [] {
    std::array<DefectComponent, kDefectCount> c{};
    for (std::size_t k = 0; k < kDefectCount; ++k)
      c[k] = DefectComponent{ kElementKeys[kMapping[k].element], kMapping[k].component };
    return c;
  }();
  return components;
}

std::string defectLabel(std::size_t index)
{
  if (index >= kDefectCount)
    throw std::out_of_range("defectLabel: index " + std::to_string(index) + " >= 30");
  return std::string(kElementKeys[kMapping[index].element]) + "." + kMapping[index].component;
}

std::size_t defectIndex(const std::string& label)
{
  std::string known;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    if (defectLabel(k) == label)
      return k;
    known += (k ? ", " : "") + defectLabel(k);
  }
  throw InputError("unknown defect '" + label + "' (the 30: " + known + ")");
}

bool DefectSet::isNominal() const
{
  for (double v : values)
  {
    if (v != 0.0)
      return false;
  }
  return true;
}

const std::array<std::string, 8>& defectJointElements()
{
  static const std::array<std::string, 8> names = { "laser_source", "galvo_x_mount", "mirror_x", "galvo_y_mount",
                                                    "mirror_y",     "window_1",      "window_2", "work_plane" };
  return names;
}

std::array<ElementDefect, 8> elementDefects(const DefectSet& set)
{
  std::array<ElementDefect, 8> out{};
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const Mapping& m = kMapping[k];
    // mm → m, mrad → rad; "+ 0.0" turns a -0 into +0 (so "-0" never reaches a URDF).
    const double si = m.sign * set.values[k] / 1000.0 + 0.0;
    ElementDefect& d = out[m.element];
    (isRotation(m.component) ? d.rotation_rad : d.translation_m)[m.our_axis] = si;
  }
  return out;
}

OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& set)
{
  OpticalGeometry g = nominal;
  const std::array<ElementDefect, 8> defects = elementDefects(set);
  for (std::size_t k = 0; k < kElementCount; ++k)
  {
    const ElementDefect& d = defects[k];
    if (d.translation_m.isZero(0.0) && d.rotation_rad.isZero(0.0))
      continue;  // identity: leave the pose bit-for-bit as it is
    // D = Trans(t) · Rz(yaw) · Ry(pitch) · Rx(roll) (URDF rpy: fixed-axis x, y, z rotations).
    Eigen::Isometry3d displacement = Eigen::Isometry3d::Identity();
    displacement.translation() = d.translation_m;
    displacement.linear() = (Eigen::AngleAxisd(d.rotation_rad.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(d.rotation_rad.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(d.rotation_rad.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
    Eigen::Isometry3d& p = pose(g, k);
    p = p * displacement;
  }
  return g;
}

DefectSet loadDefectSet(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw InputError(path + ": cannot open the defect set file");
  std::ostringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try
  {
    root = YAML::Load(text.str());
  }
  catch (const YAML::Exception& e)
  {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }

  DefectSet set;
  set.name = fileStem(path);
  if (root.IsNull())
    return set;  // empty file: the nominal machine
  const std::string format = " (a defect set maps elements to {component: value}, mm and mrad, e.g. "
                             "'mirror_x: {z: -0.025, a: -0.062, b: 0.029}'; elements: " +
                             elementList() + "; and name)";
  if (!root.IsMap())
    throw InputError(where(path, root) + ": not a map" + format);
  std::set<std::string> seen;
  std::array<bool, kDefectCount> given{};
  for (const auto& entry : root)
  {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string("(not a scalar)");
    if (!seen.insert(key).second)
      throw InputError(where(path, entry.first) + ": duplicate key '" + key + "'");
    if (key == "name")
    {
      if (!entry.second.IsScalar() || entry.second.Scalar().empty())
        throw InputError(where(path, entry.second) + ": name must be a non-empty string");
      set.name = entry.second.Scalar();
      continue;
    }
    std::size_t element = kElementCount;
    for (std::size_t k = 0; k < kElementCount; ++k)
    {
      if (key == kElementKeys[k])
        element = k;
    }
    if (element == kElementCount)
      throw InputError(where(path, entry.first) + ": unknown element '" + key + "' (elements: " + elementList() +
                       "; and name)");
    const YAML::Node& components = entry.second;
    if (components.IsNull())
      continue;  // `window_1:` with nothing: zero
    if (!components.IsMap())
      throw InputError(where(path, components) + ": " + key + " must be a map {component: value} of " +
                       allowedComponents(element));
    for (const auto& field : components)
    {
      const std::string component = field.first.IsScalar() ? field.first.Scalar() : std::string("(not a scalar)");
      const std::string label = key + "." + component;
      const std::size_t index = componentIndex(element, component);
      if (index == kDefectCount)
        throw InputError(where(path, field.first) + ": unknown component '" + label + "' (" + key + " has " +
                         allowedComponents(element) + ": OPT table 1)");
      if (given[index])
        throw InputError(where(path, field.first) + ": duplicate key '" + label + "'");
      given[index] = true;
      const std::string value_text = field.second.IsScalar() ? field.second.Scalar() : std::string("(not a scalar)");
      double value = 0.0;
      const NumberText parsed = parseNumber(value_text, value);
      if (parsed != NumberText::Ok)
        throw InputError(where(path, field.second) + ": " + label + " is " +
                         (parsed == NumberText::NotFinite ? "not finite" : "not a number") + " ('" + value_text +
                         "'; " + (isRotation(component[0]) ? "mrad" : "mm") + ")");
      set.values[index] = value;
    }
  }
  return set;
}

std::string defectSetToYaml(const DefectSet& set)
{
  YAML::Emitter name;
  name << set.name;
  std::string out =
      "# scanhead defect set (docs/defects.md): positions in mm (x, y, z), orientations in mrad (a, b, c about x, y, z)\n"
      "name: " +
      std::string(name.c_str()) + "\n";
  for (std::size_t element = 0; element < kElementCount; ++element)
  {
    std::string line = std::string(kElementKeys[element]) + ":";
    line.resize(12, ' ');
    line += "{";
    bool first = true;
    for (std::size_t k = 0; k < kDefectCount; ++k)
    {
      if (kMapping[k].element != element)
        continue;
      line += std::string(first ? "" : ", ") + kMapping[k].component + ": " + exactText(set.values[k]);
      first = false;
    }
    out += line + "}\n";
  }
  return out;
}

DefectSet optTable2DefectSet()
{
  // OPT table 2 ("Tableau 2", values drawn at random within ±0.1 mm / ±0.1 mrad), mm and mrad,
  // in the order of defectComponents(). config/defects/opt_table2.yaml holds the same numbers.
  DefectSet set;
  set.name = "opt_table2";
  set.values = {
    -0.063, -0.085, -0.069, -0.065,         // source y z b c
    -0.040, -0.023, 0.030,  0.063,  0.053,  // axis_x y z a b c
    -0.025, -0.062, 0.029,                  // mirror_x z a b
    -0.099, -0.043, -0.028, 0.018,  -0.035, // axis_y y z a b c
    0.000,  -0.075, 0.047,                  // mirror_y z a b
    -0.069, -0.013,                         // window_1 a b
    0.066,  -0.028,                         // window_2 a b
    -0.085, 0.011,  -0.045, -0.074, 0.040,  -0.003,  // work_plane x y z a b c
  };
  return set;
}

DefectSet randomDefectSet(std::uint64_t seed, double bound_mm, double bound_mrad)
{
  if (!(std::isfinite(bound_mm) && bound_mm >= 0.0) || !(std::isfinite(bound_mrad) && bound_mrad >= 0.0))
    throw ConfigError("random defect set: the bounds must be finite and >= 0 (got mm=" + exactText(bound_mm) +
                      ", mrad=" + exactText(bound_mrad) + ")");
  DefectSet set;
  set.name = "random_seed" + std::to_string(seed);
  if (bound_mm != 0.1 || bound_mrad != 0.1)
    set.name += "_mm" + exactText(bound_mm) + "_mrad" + exactText(bound_mrad);
  std::uint64_t state = seed;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    // u in [0, 1) with 53 random bits; 2u − 1 in [−1, 1) is exact, so one rounding (× bound).
    const double u = static_cast<double>(splitMix64(state) >> 11) * 0x1.0p-53;
    const double bound = isRotation(kMapping[k].component) ? bound_mrad : bound_mm;
    set.values[k] = bound * (2.0 * u - 1.0);
  }
  return set;
}

DefectSet defectSetByName(const std::string& spec)
{
  const std::string forms =
      "nominal, opt_table2, random:seed=N[,mm=B][,mrad=B] (uniform in ±B mm / ±B mrad, default 0.1) or a defect set "
      "file (.yaml)";
  if (spec == "nominal")
    return DefectSet();
  if (spec == "opt_table2")
    return optTable2DefectSet();
  auto endsWith = [&spec](const char* suffix) {
    const std::string s(suffix);
    return spec.size() > s.size() && spec.compare(spec.size() - s.size(), s.size(), s) == 0;
  };
  if (endsWith(".yaml") || endsWith(".yml"))
    return loadDefectSet(spec);
  if (spec == "random" || spec.rfind("random:", 0) == 0)
  {
    auto fail = [&](const std::string& what) {
      throw InputError("defect set '" + spec + "': " + what + " (forms: " + forms + ")");
    };
    bool has_seed = false;
    std::uint64_t seed = 0;
    double bounds[2] = { 0.1, 0.1 };
    bool has_bound[2] = { false, false };
    const std::string rest = spec.size() > 7 ? spec.substr(7) : std::string();
    std::size_t start = 0;
    while (start <= rest.size() && !rest.empty())
    {
      const std::size_t comma = rest.find(',', start);
      const std::string item = rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      const std::size_t eq = item.find('=');
      const std::string key = item.substr(0, eq);
      const std::string value = eq == std::string::npos ? std::string() : item.substr(eq + 1);
      if (eq == std::string::npos)
        fail("'" + item + "' is not key=value");
      if (key == "seed")
      {
        if (has_seed)
          fail("seed given twice");
        errno = 0;
        char* end = nullptr;
        const unsigned long long parsed = std::strtoull(value.c_str(), &end, 10);
        if (value.empty() || value.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
            errno == ERANGE)
          fail("seed must be an integer in [0, 2^64) (got '" + value + "')");
        seed = static_cast<std::uint64_t>(parsed);
        has_seed = true;
      }
      else if (key == "mm" || key == "mrad")
      {
        const int which = key == "mm" ? 0 : 1;
        if (has_bound[which])
          fail(key + " given twice");
        double bound = 0.0;
        if (parseNumber(value, bound) != NumberText::Ok || bound < 0.0)
          fail(key + " must be a number >= 0 (got '" + value + "')");
        bounds[which] = bound;
        has_bound[which] = true;
      }
      else
      {
        fail("unknown key '" + key + "' (keys: seed, mm, mrad)");
      }
      if (comma == std::string::npos)
        break;
      start = comma + 1;
    }
    if (!has_seed)
      fail("needs seed=N");
    return randomDefectSet(seed, bounds[0], bounds[1]);
  }
  throw InputError("unknown defect set '" + spec + "' (forms: " + forms + ")");
}

std::string urdfWithDefects(const std::string& nominal_urdf, const DefectSet& set, const std::string& source_name)
{
  if (set.isNominal())
  {
    return nominal_urdf;  // the URDF as it is, its own defect joints included
  }
  const UrdfText urdf(nominal_urdf);
  const std::array<ElementDefect, 8> defects = elementDefects(set);
  struct Edit
  {
    std::size_t begin, length;
    std::string text;
  };
  std::vector<Edit> edits;
  for (std::size_t k = 0; k < kElementCount; ++k)
  {
    const std::string joint = defectJointElements()[k] + "_defect_joint";
    std::size_t tag = std::string::npos;
    std::size_t tag_end = std::string::npos;
    for (std::size_t at = urdf.findTag("joint", 0); at != std::string::npos; at = urdf.findTag("joint", at + 1))
    {
      const std::size_t end = nominal_urdf.find('>', at);
      if (end == std::string::npos)
        break;
      if (urdf.attribute(at, end, "name") != joint)
        continue;
      if (tag != std::string::npos)
        throw InputError(source_name + ": joint '" + joint + "' appears twice");
      tag = at;
      tag_end = end + 1;
    }
    if (tag == std::string::npos)
      throw InputError(source_name + ": missing joint '" + joint + "' (the defect joint of element " +
                       kElementKeys[k] + ", which holds its assembly defect)");
    if (nominal_urdf[tag_end - 2] == '/')
      throw InputError(source_name + ": joint '" + joint + "' has no body (<joint .../>)");
    const std::size_t close = urdf.find("</joint>", tag_end);
    if (close == std::string::npos)
      throw InputError(source_name + ": joint '" + joint + "' is not closed (no </joint>)");
    const std::string origin = "<origin xyz=\"" + tripleText(defects[k].translation_m) + "\" rpy=\"" +
                               tripleText(defects[k].rotation_rad) + "\"/>";
    const std::size_t at = urdf.findTag("origin", tag_end, close);
    if (at != std::string::npos)
    {
      std::size_t end = nominal_urdf.find('>', at);
      if (end == std::string::npos || end > close)
        throw InputError(source_name + ": joint '" + joint + "': unterminated <origin");
      // A set replaces the defect joints of the NOMINAL head: a URDF that already carries a
      // defect would silently lose it (defects nominal keeps such a URDF as it is).
      for (const char* key : { "xyz", "rpy" })
      {
        std::istringstream numbers(urdf.attribute(at, end, key));
        for (double v = 0.0; numbers >> v;)
        {
          if (v != 0.0)
            throw InputError(source_name + ": joint '" + joint + "' already carries a defect (" + key + "=\"" +
                             urdf.attribute(at, end, key) +
                             "\"): a defect set replaces the defect joints of the nominal URDF; give the nominal "
                             "URDF, or the set nominal to use this one as it is");
        }
      }
      if (nominal_urdf[end - 1] != '/')
      {
        end = urdf.find("</origin>", end, close);
        if (end == std::string::npos)
          throw InputError(source_name + ": joint '" + joint + "': <origin> is not closed");
        end += std::string("</origin>").size() - 1;
      }
      edits.push_back({ at, end + 1 - at, origin });
    }
    else
    {
      // No origin (identity): insert one on its own line before </joint>, indented as the body.
      const std::size_t line = nominal_urdf.rfind('\n', close);
      const std::size_t line_start = line == std::string::npos ? 0 : line + 1;
      const std::string indent = nominal_urdf.substr(line_start, close - line_start);
      const bool blank = indent.find_first_not_of(" \t") == std::string::npos;
      if (blank)
        edits.push_back({ line_start, 0, indent + "  " + origin + "\n" });
      else
        edits.push_back({ close, 0, origin });
    }
  }
  std::string out = nominal_urdf;
  std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) { return a.begin > b.begin; });
  for (const Edit& e : edits)
    out.replace(e.begin, e.length, e.text);
  return out;
}
}  // namespace scanhead
