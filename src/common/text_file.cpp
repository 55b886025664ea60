/// \file text_file.cpp
#include "scanhead/common/text_file.hpp"

#include <fstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
void writeTextFile(const std::string& path, const std::string& text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.good())
    throw InputError(path + ": cannot write");
}
}  // namespace scanhead
