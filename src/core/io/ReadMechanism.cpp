#include "mobility_analysis/io/ReadMechanism.hpp"

#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "XmlValues.hpp"
#include "mobility_analysis/io/ClosureFileReader.hpp"
#include "mobility_analysis/io/LengthRange.hpp"
#include "mobility_analysis/io/MjcfReader.hpp"
#include "mobility_analysis/io/SdfReader.hpp"
#include "mobility_analysis/io/UrdfReader.hpp"

namespace mobility_analysis {

namespace {

/// The name of the document's root element, after the XML declaration, comments and doctype; "" if none.
/// @p complete (if given): the text goes on after the name (false: it may have been cut short, or be absent).
std::string rootElement(const std::string& text, bool* complete = nullptr) {
  if (complete != nullptr)
    *complete = false;
  size_t at = 0;
  while (true) {
    at = text.find('<', at);
    if (at == std::string::npos || at + 1 >= text.size())
      return "";
    const char next = text[at + 1];
    if (next == '?' || next == '!') {
      const bool comment = text.compare(at, 4, "<!--") == 0;
      const size_t close = comment ? text.find("-->", at) : text.find('>', at);
      if (close == std::string::npos)
        return "";
      at = close + 1;
      continue;
    }
    size_t end = at + 1;
    while (end < text.size() && text[end] != ' ' && text[end] != '>' && text[end] != '/' &&
           text[end] != '\n' && text[end] != '\t' && text[end] != '\r')
      ++end;
    if (complete != nullptr)
      *complete = end < text.size();
    return text.substr(at + 1, end - at - 1);
  }
}

/// How much of a file is read to find its root element [bytes].
constexpr size_t kHeadBytes = 1 << 16;

/// The first @p maxBytes of the file at @p path in @p head; @p whole: that is all of it.
bool readFileHead(const std::string& path, size_t maxBytes, std::string& head, bool& whole) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    return false;
  head.resize(maxBytes);
  const size_t got = std::fread(&head[0], 1, maxBytes, file);
  const bool ok = std::ferror(file) == 0;
  std::fclose(file);
  head.resize(got);
  whole = got < maxBytes;
  return ok;
}

Result<Mechanism> finish(Result<Mechanism> mechanism, const ReadOptions& options) {
  if (!isOk(mechanism))
    return mechanism;
  if (!options.closuresFile.empty()) {
    mechanism = addClosureFile(valueOf(std::move(mechanism)), options.closuresFile);
    if (!isOk(mechanism))
      return mechanism;
  }
  const Mechanism& m = valueOf(mechanism);
  if (std::optional<Diagnostic> outOfRange = checkLengthRange(m))
    return *outOfRange;
  if (options.strict && !m.warnings.empty()) {
    Diagnostic first = m.warnings.front();
    first.what += " (--strict: warnings are errors)";
    return first;
  }
  return mechanism;
}

/// MuJoCo reads files (and resolves includes relative to them): text goes through a private temporary file.
Result<Mechanism> readMjcfText(const std::string& text, const std::string& sourceName) {
  char path[] = "/tmp/mobility_mjcf_XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  if (fd < 0)
    return makeDiagnostic(sourceName, "mujoco", "", "cannot write a temporary file for MuJoCo");
  ::close(fd);
  {
    std::ofstream out(path);
    out << text;
  }
  Result<Mechanism> mechanism = readMjcf(path);
  std::remove(path);
  const std::string file = io_detail::baseName(sourceName);
  if (isOk(mechanism)) {
    Mechanism m = valueOf(std::move(mechanism));
    m.file = file;
    for (Diagnostic& w : m.warnings)
      w.file = file;
    return m;
  }
  Diagnostic d = diagnosticOf(mechanism);
  d.file = file;
  return d;
}

}  // namespace

Result<Mechanism> readMechanismFromString(const std::string& text, const std::string& sourceName,
                                          const ReadOptions& options) {
  const std::string root = rootElement(text);
  if (root == "mujoco")
    return finish(readMjcfText(text, sourceName), options);
  if (root == "sdf")
    return finish(readSdf(text, sourceName), options);
  return finish(readUrdf(text, sourceName, options.sideThread), options);
}

Result<Mechanism> readMechanism(const std::string& path, const ReadOptions& options) {
  // The root element from the file's head; the whole text is read only for the reader that takes text (SDF):
  // the URDF reader and MuJoCo read the file themselves, so a large URDF is in memory once.
  std::string head;
  bool whole = false;
  if (!readFileHead(path, kHeadBytes, head, whole))
    return makeDiagnostic(path, "", "", "cannot open the file");
  bool complete = false;
  std::string root = rootElement(head, &complete);
  if (!whole && !complete) {  // the head ends inside the prolog or the root's name
    if (!io_detail::readWholeFile(path, head))
      return makeDiagnostic(path, "", "", "cannot open the file");
    whole = true;
    root = rootElement(head);
  }
  if (root == "mujoco")
    return finish(readMjcf(path), options);
  const bool sdfExtension = path.size() >= 4 && path.compare(path.size() - 4, 4, ".sdf") == 0;
  if (root == "sdf" || (sdfExtension && root != "robot")) {
    if (!whole && !io_detail::readWholeFile(path, head))
      return makeDiagnostic(path, "", "", "cannot open the file");
    return finish(readSdf(head, path), options);
  }
  return finish(readUrdfFile(path, options.sideThread), options);
}

}  // namespace mobility_analysis
