/// \file test_yaml_document.cpp
/// \brief The bounded YAML reader: size limit before parsing, the expanded-node budget counted
/// independently here (aliases at every use), duplicate keys with line and column, nesting depth,
/// yaml-cpp's own deep-recursion guard, and files refused before they are read.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
std::string errorOf(const std::string& text, const YamlLimits& limits = yamlSettingsLimits("a test file"))
{
  try
  {
    parseYamlDocument(text, "t.yaml", limits);
  }
  catch (const InputError& e)
  {
    return e.what();
  }
  return "";
}

/// "l: &a [0, …, 0]" (m zeros) then "r: [*a, …]" (k uses): expanded nodes counted by hand:
/// root map 1, key l 1, list 1 + m, key r 1, list 1, then k × (1 + m) for the aliases.
std::string aliasDocument(std::size_t m, std::size_t k, std::size_t* expanded)
{
  std::string text = "l: &a [";
  for (std::size_t i = 0; i < m; ++i)
    text += i ? ",0" : "0";
  text += "]\nr: [";
  for (std::size_t i = 0; i < k; ++i)
    text += i ? ",*a" : "*a";
  text += "]\n";
  *expanded = 1 + 1 + (1 + m) + 1 + 1 + k * (1 + m);
  return text;
}
}  // namespace

TEST(YamlDocument, ReadsOrdinaryYaml)
{
  const YAML::Node root = parseYamlDocument("a: 1\nb: {c: [1, 2], d: x}\n", "t.yaml", yamlSettingsLimits("x"));
  EXPECT_EQ(root["b"]["c"][1].as<int>(), 2);
  EXPECT_EQ(root["b"]["d"].as<std::string>(), "x");
  EXPECT_TRUE(parseYamlDocument("", "t.yaml", yamlSettingsLimits("x")).IsNull());
}

TEST(YamlDocument, DuplicateKeysNameTheSecondOccurrence)
{
  EXPECT_EQ(errorOf("a: 1\nb: 2\na: 3\n"), "t.yaml:3:1: duplicate key 'a' (first at line 1)");
  EXPECT_EQ(errorOf("nc:\n  period_s: 1\n  fir_t1_s: 2\n  period_s: 3\n"),
            "t.yaml:4:3: duplicate key 'nc.period_s' (first at line 2)");
  EXPECT_EQ(errorOf("p:\n  - {x: 1, y: 2}\n  - {x: 1, x: 2}\n"),
            "t.yaml:3:12: duplicate key 'p[1].x' (first at line 3)");
  // The same key in different maps, and equal values under different keys, are fine.
  EXPECT_EQ(errorOf("a: {k: 1}\nb: {k: 1}\n"), "");
}

TEST(YamlDocument, AliasesCountAtEveryUse)
{
  const std::string ok_text = "x: &v {a: 1}\ny: *v\nz: *v\n";
  EXPECT_EQ(errorOf(ok_text), "");
  // Largest k within the budget passes, k + 1 fails (the budget is computed from each text's size).
  const std::size_t m = 200;
  std::size_t k = 1;
  for (;; ++k)
  {
    std::size_t expanded = 0, next_expanded = 0;
    const std::string text = aliasDocument(m, k, &expanded);
    const std::string next = aliasDocument(m, k + 1, &next_expanded);
    const std::size_t budget = kYamlNodesBase + kYamlNodesPerByte * text.size();
    const std::size_t next_budget = kYamlNodesBase + kYamlNodesPerByte * next.size();
    if (expanded <= budget && next_expanded > next_budget)
    {
      EXPECT_EQ(errorOf(text), "") << k;
      EXPECT_NE(errorOf(next).find("YAML aliases expand to more than " + std::to_string(next_budget) + " nodes"),
                std::string::npos)
          << errorOf(next);
      break;
    }
    ASSERT_LT(k, 1000u);
  }
  EXPECT_GT(k, 40u);  // ~10 000 / 201 nodes per use
}

TEST(YamlDocument, AliasBombStopsEarly)
{
  // 9 levels of 9 aliases: 9^9 ≈ 3.9e8 leaves from ~400 bytes; refused after ~10 800 visits.
  std::string text = "p0: &p0 [0, 0]\n";
  for (int level = 1; level <= 9; ++level)
  {
    const std::string prev = "*p" + std::to_string(level - 1);
    text += "p" + std::to_string(level) + ": &p" + std::to_string(level) + " [";
    for (int i = 0; i < 9; ++i)
      text += (i ? ", " : "") + prev;
    text += "]\n";
  }
  EXPECT_NE(errorOf(text).find("YAML aliases expand to more than"), std::string::npos);
}

TEST(YamlDocument, SizeIsCheckedBeforeParsing)
{
  YamlLimits limits;
  limits.max_bytes = 64;
  limits.what = "a YAML job";
  limits.instead = "use a CLI file";
  const std::string fits = "a: [" + std::string(58, '1') + "]\n";
  ASSERT_EQ(fits.size(), 64u);
  EXPECT_EQ(errorOf(fits, limits), "");
  // One byte more is refused even though it is not valid YAML: the size comes first.
  EXPECT_EQ(errorOf(fits + "[", limits),
            "t.yaml: 65 bytes is more than the 64 bytes a YAML job may have (YAML parsing takes ~80 bytes "
            "of memory per byte): use a CLI file");
}

TEST(YamlDocument, NestingDepthIsBounded)
{
  auto nested = [](int d) { return std::string(d, '[') + std::string(d, ']'); };
  EXPECT_EQ(errorOf(nested(kYamlMaxDepth + 1)), "");  // innermost list at depth 64
  EXPECT_NE(errorOf(nested(kYamlMaxDepth + 2)).find("YAML nested deeper than 64 levels"), std::string::npos);
  // Far deeper: yaml-cpp's own guard (depth 2000) answers, as a malformed-YAML error, not a crash.
  EXPECT_NE(errorOf(nested(100000)).find("malformed YAML"), std::string::npos);
}

TEST(YamlDocument, MalformedYamlNamesLineAndColumn)
{
  EXPECT_EQ(errorOf("a: 1\nb: [1, 2\n").rfind("t.yaml:3:", 0), 0u) << errorOf("a: 1\nb: [1, 2\n");
  EXPECT_NE(errorOf("a: 1\nb: [1, 2\n").find("malformed YAML"), std::string::npos);
}

TEST(YamlDocument, FilesAreRefusedBeforeReading)
{
  const std::string path = ::testing::TempDir() + "yaml_document_big.yaml";
  {
    std::ofstream out(path);
    out << "a: " << std::string(2000, '1') << "\n";
  }
  YamlLimits limits;
  limits.max_bytes = 1000;
  limits.what = "a config file";
  try
  {
    readYamlText(path, limits);
    ADD_FAILURE() << "no error";
  }
  catch (const InputError& e)
  {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": 2004 bytes is more than the 1000 bytes a config file", 0), 0u)
        << e.what();
  }
  limits.max_bytes = 2004;
  EXPECT_EQ(readYamlText(path, limits).size(), 2004u);
  std::remove(path.c_str());
  EXPECT_THROW(readYamlText(path, limits), InputError);  // cannot open
}
}  // namespace scanhead
