/// \file urdf_defects.cpp
/// \brief urdfWithDefects: TinyXML parses the URDF and finds the defect joints and their origins;
/// the edit is made in the given text at the positions the parser reports, so everything outside
/// the 8 origins stays byte for byte (the batch runner and the ROS graph read the same text).
///
/// TinyXML records where each node starts (row, column of its '<'), not where it ends. Parsed with
/// TIXML_ENCODING_LEGACY and a tab size of 1, a column counts bytes, so (row, column) → offset
/// through a table of line starts that breaks lines as TinyXML does ("\r\n" and "\n\r" are one
/// break, a lone '\r' or '\n' one each). The end of a node follows from the XML grammar: a start
/// tag ends at its first '>' outside quotes, a comment at "-->", CDATA at "]]>", text at the next
/// '<', an element after its last child at the '>' of its closing tag.
#include "scanhead/optics/urdf_defects.hpp"

#include <tinyxml.h>

#include <algorithm>
#include <sstream>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
std::string tripleText(const Eigen::Vector3d& v)
{
  return fullPrecisionText(v.x()) + " " + fullPrecisionText(v.y()) + " " + fullPrecisionText(v.z());
}

/// The URDF text, its TinyXML document and the node positions in the text.
class ParsedUrdf
{
public:
  ParsedUrdf(const std::string& text, const std::string& source_name)
    : text_(text)
  {
    // A UTF-8 byte order mark: the legacy encoding would not skip it, so parse after it.
    const std::size_t skip = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    line_start_.push_back(skip);
    for (std::size_t i = skip; i < text.size(); ++i)
    {
      const char c = text[i];
      if (c != '\r' && c != '\n')
        continue;
      if (i + 1 < text.size() && (text[i + 1] == '\r' || text[i + 1] == '\n') && text[i + 1] != c)
        ++i;  // "\r\n" or "\n\r": one break
      line_start_.push_back(i + 1);
    }
    document_.SetTabSize(1);
    document_.Parse(text.c_str() + skip, nullptr, TIXML_ENCODING_LEGACY);
    if (document_.Error())
      throw InputError(source_name + ": not well-formed XML (TinyXML: " + document_.ErrorDesc() + ", line " +
                       std::to_string(document_.ErrorRow()) + ", column " + std::to_string(document_.ErrorCol()) + ")");
  }

  const TiXmlDocument& document() const { return document_; }

  /// Offset of the first character of \p node (its '<' for an element or a comment).
  std::size_t begin(const TiXmlNode& node) const
  {
    return line_start_.at(static_cast<std::size_t>(node.Row() - 1)) + static_cast<std::size_t>(node.Column() - 1);
  }

  /// One past the '>' that ends the start tag of \p element.
  std::size_t startTagEnd(const TiXmlElement& element) const
  {
    char quote = 0;
    for (std::size_t i = begin(element); i < text_.size(); ++i)
    {
      const char c = text_[i];
      if (quote != 0)
        quote = c == quote ? 0 : quote;
      else if (c == '"' || c == '\'')
        quote = c;
      else if (c == '>')
        return i + 1;
    }
    return text_.size();  // not reached for a parsed document
  }

  /// `<name .../>`: no body.
  bool selfClosing(const TiXmlElement& element) const { return text_[startTagEnd(element) - 2] == '/'; }

  /// Offset of the "</name" that closes \p element. \pre !selfClosing(element)
  std::size_t closingTagBegin(const TiXmlElement& element) const
  {
    const TiXmlNode* last = element.LastChild();
    return text_.find('<', last ? end(*last) : startTagEnd(element));
  }

  /// One past the last character of \p node.
  std::size_t end(const TiXmlNode& node) const
  {
    const std::size_t at = begin(node);
    if (const TiXmlElement* element = node.ToElement())
      return selfClosing(*element) ? startTagEnd(*element) : text_.find('>', closingTagBegin(*element)) + 1;
    if (node.ToComment())
      return text_.find("-->", at + 4) + 3;
    if (const TiXmlText* text = node.ToText())
      return text->CDATA() ? text_.find("]]>", at) + 3 : text_.find('<', at);
    return text_.find('>', at) + 1;  // declaration, unknown (<!...>)
  }

private:
  const std::string& text_;
  std::vector<std::size_t> line_start_;  ///< offset of each line's first character
  TiXmlDocument document_;
};
}  // namespace

std::string urdfWithDefects(const std::string& nominal_urdf, const DefectSet& set, const std::string& source_name)
{
  if (set.isNominal())
  {
    return nominal_urdf;  // the URDF as it is, its own defect joints included
  }
  const ParsedUrdf urdf(nominal_urdf, source_name);
  const TiXmlElement* robot = urdf.document().RootElement();
  if (robot == nullptr || robot->ValueStr() != "robot")
    throw InputError(source_name + ": the root element is not <robot>");
  const std::array<ElementDefect, 8> defects = elementDefects(set);
  struct Edit
  {
    std::size_t begin, length;
    std::string text;
  };
  std::vector<Edit> edits;
  for (std::size_t k = 0; k < defects.size(); ++k)
  {
    const std::string joint = defectJointElements()[k] + "_defect_joint";
    const TiXmlElement* tag = nullptr;
    for (const TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr; j = j->NextSiblingElement("joint"))
    {
      const char* name = j->Attribute("name");
      if (name == nullptr || joint != name)
        continue;
      if (tag != nullptr)
        throw InputError(source_name + ": joint '" + joint + "' appears twice");
      tag = j;
    }
    if (tag == nullptr)
      throw InputError(source_name + ": missing joint '" + joint + "' (the defect joint of element " +
                       defectElements()[k] + ", which holds its assembly defect)");
    if (urdf.selfClosing(*tag))
      throw InputError(source_name + ": joint '" + joint + "' has no body (<joint .../>)");
    const std::string origin = "<origin xyz=\"" + tripleText(defects[k].translation_m) + "\" rpy=\"" +
                               tripleText(defects[k].rotation_rad) + "\"/>";
    if (const TiXmlElement* present = tag->FirstChildElement("origin"))
    {
      // A set replaces the defect joints of the NOMINAL head: a URDF that already carries a
      // defect would silently lose it (defects nominal keeps such a URDF as it is).
      for (const char* key : {"xyz", "rpy"})
      {
        const char* value = present->Attribute(key);
        std::istringstream numbers(value ? value : "");
        for (double v = 0.0; numbers >> v;)
        {
          if (v != 0.0)
            throw InputError(source_name + ": joint '" + joint + "' already carries a defect (" + key + "=\"" + value +
                             "\"): a defect set replaces the defect joints of the nominal URDF; give the nominal "
                             "URDF, or the set nominal to use this one as it is");
        }
      }
      const std::size_t at = urdf.begin(*present);
      edits.push_back({at, urdf.end(*present) - at, origin});
    }
    else
    {
      // No origin (identity): insert one on its own line before </joint>, indented as the body.
      const std::size_t close = urdf.closingTagBegin(*tag);
      const std::size_t line = nominal_urdf.rfind('\n', close);
      const std::size_t line_start = line == std::string::npos ? 0 : line + 1;
      const std::string indent = nominal_urdf.substr(line_start, close - line_start);
      const bool blank = indent.find_first_not_of(" \t") == std::string::npos;
      if (blank)
        edits.push_back({line_start, 0, indent + "  " + origin + "\n"});
      else
        edits.push_back({close, 0, origin});
    }
  }
  std::string out = nominal_urdf;
  std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) { return a.begin > b.begin; });
  for (const Edit& e : edits)
    out.replace(e.begin, e.length, e.text);
  return out;
}
}  // namespace scanhead
