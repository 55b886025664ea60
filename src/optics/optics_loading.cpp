#include "scanhead/optics/optics_loading.hpp"

#include "scanhead/common/package_path.hpp"
#include "scanhead/optics/defect_set_spec.hpp"
#include "scanhead/optics/urdf_defects.hpp"

namespace scanhead
{
OpticalModel loadOpticalModel(const OpticsConfig& config)
{
  // Through the URDF text of the defective machine, as the graph reads it from robot_description:
  // the same parser on the same numbers, so the batch runner and the graph are bit-identical.
  const std::string path = resolvePackagePath(config.urdf_path);
  return OpticalModel(geometryFromUrdf(urdfWithDefects(readUrdfFile(path), loadDefects(config), path), path), config);
}

DefectSet loadDefects(const OpticsConfig& config)
{
  const std::string& spec = config.defects;
  const bool file = spec.size() > 5 &&
                    (spec.compare(spec.size() - 5, 5, ".yaml") == 0 || spec.compare(spec.size() - 4, 4, ".yml") == 0);
  return defectSetByName(file ? resolvePackagePath(spec) : spec);
}
}  // namespace scanhead
