#include "XmlHalves.hpp"

#include <cctype>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>

#include <sys/stat.h>

#include "../SideTask.hpp"

namespace mobility_analysis {
namespace io_detail {

namespace {

/// Bytes past the place asked for in which a cut is looked for (a URDF's top-level elements are a few
/// hundred bytes long).
constexpr size_t kSeamWindow = size_t{1} << 16;

bool isBlank(char c) {
  return c == ' ' || c == '\t';
}

/// Whether @p text holds an element named @p name at @p at (its '<'): the name, then a blank, '>' or '/'.
bool startsElement(std::string_view text, size_t at, std::string_view name) {
  if (text.compare(at + 1, name.size(), name) != 0 || at + 1 + name.size() >= text.size())
    return false;
  const char next = text[at + 1 + name.size()];
  return next == ' ' || next == '\t' || next == '\n' || next == '\r' || next == '>' || next == '/';
}

/**
 * The blanks that open the line of the root's first child, when that child starts a line of its own: the
 * indentation a top-level element is written at. Comments and processing instructions before it are
 * skipped; quoted attribute values may hold '>'.
 */
std::optional<std::string_view> childIndentation(std::string_view text, std::string_view root) {
  size_t at = 0;
  while ((at = text.find('<', at)) != std::string_view::npos && !startsElement(text, at, root))
    ++at;
  if (at == std::string_view::npos)
    return std::nullopt;
  for (char quote = 0; ++at < text.size() && (quote != 0 || text[at] != '>');) {
    if (text[at] == '"' || text[at] == '\'')
      quote = quote == 0 ? text[at] : (quote == text[at] ? 0 : quote);
  }
  while ((at = text.find('<', at)) != std::string_view::npos) {
    if (text.compare(at, 4, "<!--") == 0) {
      at = text.find("-->", at);
    } else if (text.compare(at, 2, "<?") == 0) {
      at = text.find("?>", at);
    } else {
      break;
    }
    if (at == std::string_view::npos)
      return std::nullopt;
  }
  if (at == std::string_view::npos)
    return std::nullopt;
  size_t lineStart = at;
  while (lineStart > 0 && isBlank(text[lineStart - 1]))
    --lineStart;
  if (lineStart == 0 || text[lineStart - 1] != '\n')
    return std::nullopt;
  return text.substr(lineStart, at - lineStart);
}

/// The '<' of the first element from @p from on that starts a line at @p indentation, or npos.
size_t findCut(std::string_view text, size_t from, std::string_view indentation) {
  for (size_t line = text.find('\n', from == 0 ? 0 : from - 1); line != std::string_view::npos;
       line = text.find('\n', line + 1)) {
    const size_t at = line + 1 + indentation.size();
    if (at + 1 < text.size() && text.compare(line + 1, indentation.size(), indentation) == 0 &&
        text[at] == '<' && (std::isalpha(static_cast<unsigned char>(text[at + 1])) || text[at + 1] == '_'))
      return at;
  }
  return std::string_view::npos;
}

/// @p count bytes of @p file from byte @p at into @p out; false when fewer could be read.
bool readAt(std::FILE* file, size_t at, size_t count, char* out) {
  return std::fseek(file, static_cast<long>(at), SEEK_SET) == 0 && std::fread(out, 1, count, file) == count;
}

/// Whether @p document's top-level nodes are as XmlHalves takes them: no text, and one element, @p root,
/// first when @p rootFirst (the second half), last otherwise (the first).
bool takenAsHalf(const pugi::xml_document& document, const char* root, bool rootFirst) {
  int elements = 0;
  for (pugi::xml_node top = document.first_child(); top; top = top.next_sibling()) {
    const pugi::xml_node_type type = top.type();
    if (type == pugi::node_pcdata || type == pugi::node_cdata)
      return false;
    if (type == pugi::node_element) {
      ++elements;
      if (std::strcmp(top.name(), root) != 0)
        return false;
    }
  }
  const pugi::xml_node end = rootFirst ? document.first_child() : document.last_child();
  return elements == 1 && end.type() == pugi::node_element;
}

}  // namespace

std::unique_ptr<XmlHalves> parseInHalves(const std::string& path, unsigned options, const char* root,
                                         size_t minBytes, std::optional<size_t> cutFrom) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode) ||
      static_cast<size_t>(status.st_size) < minBytes)
    return nullptr;
  const size_t size = static_cast<size_t>(status.st_size);
  const size_t from = cutFrom ? *cutFrom : size / 2;
  if (from >= size)
    return nullptr;
  const std::string endTag = std::string("</") + root + ">";
  const std::string startTag = std::string("<") + root + ">";
  const size_t gap = endTag.size() + 1 + startTag.size();

  // Where to cut, from the file's head (the indentation of the root's first child) and a window at `from`;
  // then the file read in two pieces around the gap the seam is written in.
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    return nullptr;
  std::string head(std::min(size, kSeamWindow), '\0');
  const size_t windowStart = from == 0 ? 0 : from - 1;
  std::string window(std::min(size - windowStart, kSeamWindow), '\0');
  std::optional<std::string_view> indentation;
  size_t cut = std::string_view::npos;
  if (readAt(file, 0, head.size(), &head[0]) && readAt(file, windowStart, window.size(), &window[0]) &&
      (indentation = childIndentation(head, root))) {
    cut = findCut(window, from - windowStart, *indentation);
    if (cut != std::string_view::npos)
      cut += windowStart;
  }
  auto halves = std::make_unique<XmlHalves>();
  std::string& text = halves->text;
  bool read = false;
  if (cut != std::string_view::npos) {
    text.resize(size + gap);
    read = readAt(file, 0, cut, &text[0]) && readAt(file, cut, size - cut, &text[cut + gap]) &&
           std::fgetc(file) == EOF;
  }
  std::fclose(file);
  if (!read)
    return nullptr;
  text.replace(cut, gap, endTag + ' ' + startTag);
  halves->cut = cut;

  const size_t secondStart = cut + endTag.size() + 1;
  core_detail::SideTask<pugi::xml_parse_result> second(true, [&] {
    return halves->second.load_buffer_inplace(&text[secondStart], text.size() - secondStart, options,
                                              pugi::encoding_utf8);
  });
  const pugi::xml_parse_result first =
      halves->first.load_buffer_inplace(&text[0], cut + endTag.size(), options, pugi::encoding_auto);
  const pugi::xml_parse_result secondParsed = second.get();
  if (!first || !secondParsed || first.encoding != pugi::encoding_utf8 ||
      !takenAsHalf(halves->first, root, false) || !takenAsHalf(halves->second, root, true))
    return nullptr;
  return halves;
}

}  // namespace io_detail
}  // namespace mobility_analysis
