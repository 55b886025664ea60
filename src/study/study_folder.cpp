/// \file study_folder.cpp
/// \brief The study folder's files (study_folder.hpp).
#include "scanhead/study/study_folder.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

/// \brief The value of "key: value" in a small YAML file written by writeCaseStatus (one key a line).
std::string statusValue(const std::string& text, const std::string& key)
{
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.compare(0, key.size() + 2, key + ": ") == 0)
      return line.substr(key.size() + 2);
  return "";
}

/// \brief Tabs and line breaks of a field of cases.tsv turned into blanks (the file is one case a line).
std::string field(const std::string& text)
{
  std::string out = text;
  for (char& c : out)
    if (c == '\t' || c == '\n' || c == '\r')
      c = ' ';
  return out;
}
}  // namespace

std::string caseResultsDir(const std::string& dir, const std::string& id)
{
  return (fs::path(dir) / "cases" / id).string();
}
std::string caseConfigPath(const std::string& dir, const std::string& id)
{
  return (fs::path(dir) / "configs" / (id + ".yaml")).string();
}
std::string caseLogPath(const std::string& dir, const std::string& id)
{
  return (fs::path(dir) / "logs" / (id + ".log")).string();
}

void writeFileWhole(const std::string& path, const std::string& text)
{
  const std::string staging = path + ".tmp" + std::to_string(::getpid());
  writeTextFile(staging, text);
  std::error_code ec;
  fs::rename(staging, path, ec);
  if (ec)
  {
    fs::remove(staging);
    throw InputError(path + ": cannot write (" + ec.message() + ")");
  }
}

void writeStudyPlan(const std::string& dir, const std::string& study_text, const std::vector<StudyCase>& cases)
{
  for (const char* sub : {"configs", "cases", "status", "logs"})
    fs::create_directories(fs::path(dir) / sub);
  writeFileWhole((fs::path(dir) / "study.yaml").string(), study_text);
  std::string tsv = "index\tid\tjob\tlayer\tgrid\n";
  for (std::size_t i = 0; i < cases.size(); ++i)
  {
    const StudyCase& c = cases[i];
    std::string grid;
    for (const auto& [key, value] : c.grid)
      grid += (grid.empty() ? "" : ";") + key + "=" + value;
    tsv += std::to_string(i) + "\t" + c.id + "\t" + field(c.job) + "\t" + std::to_string(c.layer) + "\t" + field(grid) +
           "\n";
    const std::string config = caseConfigPath(dir, c.id);
    if (!fs::exists(config) || readFileOrEmpty(config) != c.config_yaml)
      writeFileWhole(config, c.config_yaml);
  }
  writeFileWhole((fs::path(dir) / "cases.tsv").string(), tsv);
}

std::vector<CaseRecord> readStudyCases(const std::string& dir)
{
  const fs::path tsv = fs::path(dir) / "cases.tsv";
  std::ifstream in(tsv);
  if (!in)
    throw InputError(dir + ": not a study folder (no cases.tsv; `scanhead_study run STUDY.yaml --out " + dir +
                     "` makes one)");
  std::vector<CaseRecord> records;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line))
  {
    std::vector<std::string> parts;
    std::istringstream fields(line);
    for (std::string part; std::getline(fields, part, '\t');)
      parts.push_back(part);
    if (parts.size() < 4)
      throw InputError(tsv.string() + ":" + std::to_string(records.size() + 2) + ": expected index, id, job, layer");
    CaseRecord r;
    r.index = records.size();
    r.id = parts[1];
    r.job = parts[2];
    r.layer = std::atoi(parts[3].c_str());
    r.grid_text = parts.size() > 4 ? parts[4] : "";
    const std::string status = readFileOrEmpty((fs::path(dir) / "status" / (r.id + ".yaml")).string());
    const bool published = fs::exists(fs::path(caseResultsDir(dir, r.id)) / "metrics.yaml");
    const std::string said = statusValue(status, "status");
    if (said == "failed" && !published)
      r.state = CaseState::Failed;
    else if (published)
      r.state = CaseState::Done;
    if (!status.empty())
    {
      r.exit_code = std::atoi(statusValue(status, "exit_code").c_str());
      double wall = -1.0;
      if (parseNumber(statusValue(status, "wall_s"), wall) == NumberText::Ok)
        r.wall_s = wall;
      r.error = statusValue(status, "error");
      if (r.error.size() >= 2 && r.error.front() == '"')
        r.error = r.error.substr(1, r.error.size() - 2);
    }
    records.push_back(std::move(r));
  }
  return records;
}

void writeCaseStatus(const std::string& dir, const std::string& id, bool done, int exit_code, double wall_s,
                     const std::string& error)
{
  std::string text = std::string("status: ") + (done ? "done" : "failed") + "\n";
  text += "exit_code: " + std::to_string(exit_code) + "\n";
  text += "wall_s: " + sixDigitText(wall_s) + "\n";
  std::string quoted = error;
  for (char& c : quoted)
    if (c == '"' || c == '\n')
      c = '\'';
  text += "error: \"" + quoted + "\"\n";
  writeFileWhole((fs::path(dir) / "status" / (id + ".yaml")).string(), text);
}

std::string errorLineOf(const std::string& log)
{
  std::istringstream lines(log);
  std::string last, error;
  for (std::string line; std::getline(lines, line);)
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    last = line;
    if (line.find("error:") != std::string::npos || line.find("Error") != std::string::npos)
      error = line;
  }
  return error.empty() ? last : error;
}
}  // namespace scanhead
