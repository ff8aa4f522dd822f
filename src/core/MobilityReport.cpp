#include "mobility_analysis/MobilityReport.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <ostream>
#include <sstream>
#include <vector>

#include "JsonHalves.hpp"
#include "SideTask.hpp"

namespace mobility_analysis {

const char* toString(ElementClass elementClass) {
  switch (elementClass) {
    case ElementClass::Neutral:
      return "neutral";
    case ElementClass::OverConstrainedLoop:
      return "over_constrained_loop";
    case ElementClass::Redundant:
      return "redundant";
  }
  return "unknown";
}

namespace {

/**
 * @brief Appends to a string through a fixed buffer: one std::string::append per few kilobytes instead of one
 *        per piece (the links, joints and positions of a chain of 10^5 links are 3 10^5 records of about ten
 *        pieces each, and each append is a call with its own capacity check). Flushed when destroyed.
 */
class BufferedAppender {
 public:
  /// With @p stream, @p out is only a chunk: passed on to the stream whenever it holds kStreamChunk bytes,
  /// and at the end.
  explicit BufferedAppender(std::string& out, std::ostream* stream = nullptr) : out_(out), stream_(stream) {}
  BufferedAppender(const BufferedAppender&) = delete;
  BufferedAppender& operator=(const BufferedAppender&) = delete;
  ~BufferedAppender() {
    flush();
    if (stream_)
      passOn();
  }

  void append(const char* data, size_t size) {
    if (used_ + size > sizeof(buffer_)) {
      flush();
      if (size > sizeof(buffer_)) {
        out_.append(data, size);
        return;
      }
    }
    std::memcpy(buffer_ + used_, data, size);
    used_ += size;
  }
  void append(const char* first, const char* last) { append(first, static_cast<size_t>(last - first)); }
  void append(const std::string& text, size_t at, size_t size) { append(text.data() + at, size); }
  BufferedAppender& operator+=(char c) {
    if (used_ == sizeof(buffer_))
      flush();
    buffer_[used_++] = c;
    return *this;
  }
  BufferedAppender& operator+=(const char* text) {
    append(text, std::strlen(text));
    return *this;
  }
  BufferedAppender& operator+=(const std::string& text) {
    append(text.data(), text.size());
    return *this;
  }

 private:
  // Why chunks of a megabyte: few enough writes, and a report of any size touches no more fresh memory than
  // that (a 200 x 200 braced lattice's text is 82 MB, a 10^6-link chain's 215 MB).
  static constexpr size_t kStreamChunk = size_t{1} << 20;

  void flush() {
    out_.append(buffer_, used_);
    used_ = 0;
    if (stream_ && out_.size() >= kStreamChunk)
      passOn();
  }
  void passOn() {
    stream_->write(out_.data(), static_cast<std::streamsize>(out_.size()));
    out_.clear();
  }

  std::string& out_;
  std::ostream* stream_;
  char buffer_[4096];
  size_t used_ = 0;
};

/// Per byte: whether it goes into a JSON string as it is (printable ASCII but '"' and '\\').
struct PlainBytes {
  bool plain[256] = {};
  constexpr PlainBytes() {
    for (int c = 0x20; c < 0x80; ++c)
      plain[c] = c != '"' && c != '\\';
  }
};
constexpr PlainBytes kPlainBytes;

template <class Out>
void appendQuoted(Out& out, const std::string& text) {
  out += '"';
  for (size_t i = 0; i < text.size(); ++i) {
    // A run of characters that need no escape goes in at once (most names are all of one run); one table
    // look-up a byte.
    size_t plain = i;
    while (plain < text.size() && kPlainBytes.plain[static_cast<unsigned char>(text[plain])])
      ++plain;
    if (plain > i) {
      out.append(text, i, plain - i);
      i = plain - 1;
      continue;
    }
    const char c = text[i];
    if (static_cast<unsigned char>(c) >= 0x80) {  // JSON is UTF-8: a byte outside a valid sequence is U+FFFD
      const int length = utf8SequenceLength(text, i);
      if (length == 0) {
        out += "\\ufffd";
      } else {
        out.append(text, i, static_cast<size_t>(length));
        i += static_cast<size_t>(length) - 1;
      }
      continue;
    }
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

std::string quote(const std::string& text) {
  std::string out;
  appendQuoted(out, text);
  return out;
}

/// Numbers with a fixed number of significant digits, so equal reports print equal text. JSON has no inf or
/// nan: a non-finite number is written as null (writeJson refuses such a report before it gets here).
/// std::to_chars in the general format with a precision is printf's %.*g in the C locale, several times
/// faster (a report of a large grid writes millions of forces).
template <class Out>
void appendNumber(Out& out, double value, int digits = 9) {
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  char text[40];
  const std::to_chars_result written =
      std::to_chars(text, text + sizeof(text), value, std::chars_format::general, digits);
  out.append(text, written.ptr);
}

std::string number(double value, int digits = 9) {
  std::string out;
  appendNumber(out, value, digits);
  return out;
}

template <class T, class F>
std::string array(const std::vector<T>& items, F&& write) {
  std::string out = "[";
  for (size_t i = 0; i < items.size(); ++i) {
    if (i)
      out += ", ";
    out += write(items[i]);
  }
  return out + "]";
}

/// {"name": …, "kind": …, "force": …}, appended (the states of a large grid hold millions of these).
template <class Out>
void appendForce(Out& out, const ElementForce& f) {
  out += "{\"name\": ";
  appendQuoted(out, f.name);
  out += ", \"kind\": ";
  appendQuoted(out, f.kind);
  out += ", \"force\": ";
  appendNumber(out, f.force);
  out += '}';
}

template <class Out>
void appendForces(Out& out, const std::vector<ElementForce>& forces) {
  out += '[';
  for (size_t i = 0; i < forces.size(); ++i) {
    if (i)
      out += ", ";
    appendForce(out, forces[i]);
  }
  out += ']';
}

std::string cableJson(const CableState& c) {
  return "{\"name\": " + quote(c.name) + ", \"type\": " + quote(c.type) + ", \"state\": " + quote(c.state) +
         ", \"length\": " + number(c.length) + ", \"distance\": " + number(c.distance) + "}";
}

std::string deploymentJson(const DeploymentInfo& d) {
  std::string out =
      "{\"cable\": " + quote(d.cable) + ", \"initial_length\": " + number(d.initialLength) +
      ", \"target_length\": " + number(d.targetLength) + ", \"final_length\": " + number(d.finalLength, 12) +
      ", \"final_dof\": " + std::to_string(d.finalDof) + ", \"stopped_by\": " + array(d.stoppedBy, quote) +
      ", \"reason\": " + quote(d.reason) + ",\n    \"steps\": [";
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const DeploymentStep& step = d.steps[i];
    out += std::string(i ? ",\n      " : "\n      ") +
           "{\"active_length\": " + number(step.activeLength, 12) + ", \"dof\": " + std::to_string(step.dof) +
           ", \"cables\": " + array(step.cables, cableJson) + ", \"joints\": {";
    for (size_t j = 0; j < step.joints.size(); ++j)
      out += (j ? ", " : "") + quote(step.joints[j].name) + ": " + number(step.joints[j].value, 12);
    out += "}}";
  }
  return out + "]}";
}

/// The JSON of @p r appended to @p text.
/**
 * The JSON text of a report as a sequence of parts, each written on its own, in order: a part is a fixed text
 * and, for the long lists (states, joints, links, redundant constraints, the nullity trace, positions), its
 * items, each part's opening and closing text around them. The concatenation of the parts is the report, byte
 * for byte, wherever it is cut; toJson cuts a large report in two at about half its bytes and writes the
 * halves on two threads.
 */
class JsonParts {
 public:
  explicit JsonParts(const MobilityReport& r);

  /// A place in the text: before part @p part when @p item is 0, else within its list, after its opening and
  /// its first @p item items.
  struct Cut {
    size_t part = 0;
    size_t item = 0;
  };
  Cut begin() const { return {}; }
  Cut end() const { return {parts_.size(), 0}; }
  /// About half of the estimated bytes on either side.
  Cut middle() const;
  size_t estimatedBytes() const { return total_; }
  /// Appends the text from @p from to @p to; with @p stream, writes it there, @p text holding a chunk at a
  /// time.
  void write(std::string& text, Cut from, Cut to, std::ostream* stream = nullptr) const;
  /// write from begin() to end(), the second half (from middle()) on another thread once the estimate
  /// reaches @p secondThreadFrom bytes: into its own string, then appended (the copy costs a fiftieth of the
  /// writing) or written to @p stream.
  void writeAll(std::string& text, size_t secondThreadFrom, std::ostream* stream) const;

 private:
  struct Part {
    std::function<void(BufferedAppender&)> open, close;
    size_t items = 0;
    std::function<void(BufferedAppender&, size_t)> item;  // item i, without the ", " before it
    size_t fixedBytes = 0, itemBytes = 0;                 // estimates
  };
  using Writer = std::function<void(BufferedAppender&)>;
  using ItemWriter = std::function<void(BufferedAppender&, size_t)>;
  void addFixed(size_t bytes, Writer write);
  /// A list field: its opening ("  \"name\": [") , its items, and its close up to the next part.
  void addList(size_t items, size_t itemBytes, Writer open, ItemWriter item, Writer close);
  void addHead(const MobilityReport& r);
  void addRedundancy(const MobilityReport& r);
  void addElements(const MobilityReport& r);
  void addPose(const MobilityReport& r);
  void addSelfStress(const MobilityReport& r);
  void addTail(const MobilityReport& r);
  void writePart(BufferedAppender& out, const Part& part, size_t from, size_t to, bool open,
                 bool close) const;

  std::vector<Part> parts_;
  size_t total_ = 0;
};

/// From this many estimated bytes on, toJson writes the report's second half on a second thread: about 5 ms
/// of writing, against tens of microseconds to start a thread.
constexpr size_t kJsonSideThreadBytes = size_t{1} << 22;

}  // namespace

std::string toJson(const MobilityReport& r) {
  return toJson(r, true);
}

std::string toJson(const MobilityReport& r, bool sideThread) {
  return core_detail::toJson(r, sideThread ? kJsonSideThreadBytes : std::numeric_limits<size_t>::max());
}

std::string core_detail::toJson(const MobilityReport& r, size_t secondThreadFrom) {
  // One string, appended to in place (through a buffer, BufferedAppender): the links, joints and positions of
  // a 10^5-link chain are 3 10^5 small objects, each once built apart and copied in.
  // Room for all of it at once, from the sizes of its parts: grown by doubling from too small a guess, a
  // report whose listed states are most of it (a 100 x 100 grid of continuous bars: 21 MB, 19 800 states)
  // was copied three times over and touched 36 MB of fresh pages. The estimates are each record's fixed text
  // with its numbers.
  const JsonParts parts(r);
  const size_t size = parts.estimatedBytes();
  std::string text;
  text.reserve(size + size / 16);  // a margin: a doubling at the very end would copy all of it once more
  parts.writeAll(text, secondThreadFrom, nullptr);
  return text;
}

void core_detail::writeJson(const MobilityReport& r, std::ostream& out, size_t secondThreadFrom) {
  // As toJson, but the text goes to the stream as it is written instead of into one string: the first half
  // never exists whole, and the second (when on another thread) only until it is written.
  std::string chunk;
  JsonParts(r).writeAll(chunk, secondThreadFrom, &out);
}

namespace {

// Writers of the pieces the parts are made of.
void appendInteger(BufferedAppender& out, long long value) {
  char digits[24];
  out.append(digits, std::to_chars(digits, digits + sizeof(digits), value).ptr);
}
void appendBoolean(BufferedAppender& out, bool value) {
  out += value ? "true" : "false";
}
void appendField(BufferedAppender& out, const char* name) {  // "  \"name\": "
  out += "  \"";
  out += name;
  out += "\": ";
}
/// "[a, b, …]" with each item appended by @p write.
template <class Items, class Write>
void appendList(BufferedAppender& out, const Items& items, Write&& write) {
  out += '[';
  for (size_t i = 0; i < items.size(); ++i) {
    if (i)
      out += ", ";
    write(items[i]);
  }
  out += ']';
}
void appendStatus(BufferedAppender& out, const ElementStatus& e) {
  out += "{\"name\": ";
  appendQuoted(out, e.name);
  out += ", \"kind\": ";
  appendQuoted(out, e.kind);
  out += ", \"type\": ";
  appendQuoted(out, e.type);
  out += ", \"class\": \"";
  out += toString(e.elementClass);  // a fixed word, nothing to escape
  out += '"';
  out += '}';
}
size_t forcesBytes(const std::vector<ElementForce>& elements) {
  size_t bytes = 2;
  for (const ElementForce& element : elements)  // {"name": "", "kind": "", "force": } and a number
    bytes += 48 + element.name.size() + element.kind.size();
  return bytes;
}

/// Opens a field: "  \"name\": " and the bracket.
std::function<void(BufferedAppender&)> fieldOpen(const char* name, char bracket) {
  return [name, bracket](BufferedAppender& out) {
    appendField(out, name);
    out += bracket;
  };
}

std::function<void(BufferedAppender&)> closeWith(const char* text) {
  return [text](BufferedAppender& out) { out += text; };
}

JsonParts::JsonParts(const MobilityReport& r) {
  addHead(r);
  addRedundancy(r);
  addElements(r);
  addPose(r);
  addSelfStress(r);
  addTail(r);
  for (const Part& part : parts_)
    total_ += part.fixedBytes + part.items * part.itemBytes;
}

void JsonParts::addFixed(size_t bytes, Writer write) {
  Part part;
  part.open = std::move(write);
  part.fixedBytes = bytes;
  parts_.push_back(std::move(part));
}

void JsonParts::addList(size_t items, size_t itemBytes, Writer open, ItemWriter item, Writer close) {
  Part part;
  part.open = std::move(open);
  part.close = std::move(close);
  part.items = items;
  part.item = std::move(item);
  part.fixedBytes = 64;
  part.itemBytes = itemBytes;
  parts_.push_back(std::move(part));
}

/// From "{" to the passive motions.
void JsonParts::addHead(const MobilityReport& r) {
  addFixed(1024, [&r](BufferedAppender& out) {
    out += "{\n";
    const std::pair<const char*, const std::string*> names[] = {
        {"robot", &r.robot}, {"file", &r.file}, {"mode", &r.mode}};
    for (const auto& [name, text] : names) {
      appendField(out, name);
      appendQuoted(out, *text);
      out += ",\n";
    }
    const std::pair<const char*, int> counts[] = {{"lambda", r.lambda},
                                                  {"dof", r.dof},
                                                  {"grubler_kutzbach_dof", r.grublerKutzbachDof},
                                                  {"num_coordinates", r.numCoordinates},
                                                  {"num_constraints", r.numConstraints},
                                                  {"rank", r.rank},
                                                  {"num_redundant", r.numRedundant},
                                                  {"finite_dof", r.finiteDof}};
    for (const auto& [name, value] : counts) {
      appendField(out, name);
      appendInteger(out, value);
      out += ",\n";
    }
    appendField(out, "singular");
    appendBoolean(out, r.singular);
    out += ",\n";
    for (const auto& [name, value] : {std::pair<const char*, int>{"passive_dof", r.passiveDof},
                                      std::pair<const char*, int>{"output_dof", r.outputDof}}) {
      appendField(out, name);
      appendInteger(out, value);
      out += ",\n";
    }
    appendField(out, "passive_motions");
    appendList(out, r.passiveMotions, [&](const PassiveMotion& m) {
      out += "{\"links\": ";
      appendList(out, m.links, [&](const std::string& link) { appendQuoted(out, link); });
      out += ", \"description\": ";
      appendQuoted(out, m.description);
      out += '}';
    });
    out += ",\n";
  });
}

/// The nullity trace and the redundant constraints, joints, links and boundaries.
void JsonParts::addRedundancy(const MobilityReport& r) {
  addList(
      r.nullityTrace.size(), 8, fieldOpen("nullity_trace", '['),
      [&r](BufferedAppender& out, size_t i) { appendInteger(out, r.nullityTrace[i]); }, closeWith("],\n"));
  size_t constraintBytes = 96;
  for (const RedundantConstraint& c : r.redundantConstraints)
    constraintBytes += c.source.size() + c.name.size() + c.kind.size() + c.equation.size() + c.cause.size();
  addList(
      r.redundantConstraints.size(),
      r.redundantConstraints.empty() ? 96 : constraintBytes / r.redundantConstraints.size(),
      fieldOpen("redundant_constraints", '['),
      [&r](BufferedAppender& out, size_t i) {
        const RedundantConstraint& c = r.redundantConstraints[i];
        out += "{\"index\": ";
        appendInteger(out, c.index);
        out += ", \"source\": ";
        appendQuoted(out, c.source);
        out += ", \"name\": ";
        appendQuoted(out, c.name);
        out += ", \"kind\": ";
        appendQuoted(out, c.kind);
        out += ", \"equation\": ";
        appendQuoted(out, c.equation);
        out += ", \"cause\": ";
        appendQuoted(out, c.cause);
        out += '}';
      },
      closeWith("],\n"));
  addList(
      r.redundantJoints.size(), 80, fieldOpen("redundant_joints", '['),
      [&r](BufferedAppender& out, size_t i) {
        const RedundantJoint& j = r.redundantJoints[i];
        out += "{\"name\": ";
        appendQuoted(out, j.name);
        out += ", \"redundant_equations\": ";
        appendInteger(out, j.redundantEquations);
        out += ", \"equations\": ";
        appendInteger(out, j.equations);
        out += '}';
      },
      closeWith("],\n"));
  addFixed(64 + 32 * (r.redundantLinks.size() + r.redundantBoundaries.size()), [&r](BufferedAppender& out) {
    auto quoted = [&out](const std::string& text) { appendQuoted(out, text); };
    appendField(out, "redundant_links");
    appendList(out, r.redundantLinks, quoted);
    out += ",\n";
    appendField(out, "redundant_links_computed");
    appendBoolean(out, r.redundantLinksComputed);
    out += ",\n";
    appendField(out, "redundant_boundaries");
    appendList(out, r.redundantBoundaries, quoted);
    out += ",\n";
  });
}

/// Every link, joint and cable with its class or state.
void JsonParts::addElements(const MobilityReport& r) {
  addList(
      r.links.size(), 96, fieldOpen("links", '['),
      [&r](BufferedAppender& out, size_t i) { appendStatus(out, r.links[i]); }, closeWith("],\n"));
  addList(
      r.joints.size(), 96, fieldOpen("joints", '['),
      [&r](BufferedAppender& out, size_t i) { appendStatus(out, r.joints[i]); }, closeWith("],\n"));
  addList(
      r.cables.size(), 112, fieldOpen("cables", '['),
      [&r](BufferedAppender& out, size_t i) {
        const CableState& c = r.cables[i];
        out += "{\"name\": ";
        appendQuoted(out, c.name);
        out += ", \"type\": ";
        appendQuoted(out, c.type);
        out += ", \"state\": ";
        appendQuoted(out, c.state);
        out += ", \"length\": ";
        appendNumber(out, c.length);
        out += ", \"distance\": ";
        appendNumber(out, c.distance);
        out += '}';
      },
      closeWith("],\n"));
}

/// The rank margin, scale, closure, joint positions and assembly.
void JsonParts::addPose(const MobilityReport& r) {
  addFixed(256, [&r](BufferedAppender& out) {
    appendField(out, "rank_margin");
    out += "{\"tolerance\": ";
    appendNumber(out, r.rankMargin.tolerance, 3);
    out += ", \"smallest_kept_pivot\": ";
    appendNumber(out, r.rankMargin.smallestKeptPivot, 3);
    out += ", \"largest_dropped_residual\": ";
    appendNumber(out, r.rankMargin.largestDroppedResidual, 3);
    out += ", \"near_tolerance\": ";
    appendBoolean(out, r.rankMargin.nearTolerance);
    out += "},\n";
    appendField(out, "characteristic_length");
    appendNumber(out, r.characteristicLength);
    out += ",\n";
    appendField(out, "closure_residual");
    out += "{\"before\": ";
    appendNumber(out, r.closureResidualBefore, 3);
    out += ", \"after\": ";
    appendNumber(out, r.closureResidualAfter, 3);
    out += "},\n";
  });
  addList(
      r.positions.size(), 48, fieldOpen("positions", '{'),
      [&r](BufferedAppender& out, size_t i) {
        appendQuoted(out, r.positions[i].name);
        out += ": ";
        appendNumber(out, r.positions[i].value, 12);
      },
      closeWith("},\n"));
  addFixed(128 + 16 * r.assembly.events.size(), [&r](BufferedAppender& out) {
    appendField(out, "assembly");
    out += "{\"residual\": ";
    appendNumber(out, r.assembly.residual, 3);
    out += ", \"steps\": ";
    appendInteger(out, r.assembly.steps);
    out += ", \"iterations\": ";
    appendInteger(out, r.assembly.iterations);
    out += ", \"events\": ";
    appendList(out, r.assembly.events, [&out](const std::string& text) { appendQuoted(out, text); });
    out += "},\n";
  });
}

/// self_stress: its states, then its prestress, each a list of its own.
void JsonParts::addSelfStress(const MobilityReport& r) {
  const SelfStressInfo& s = r.selfStress;
  size_t stateBytes = 0;
  for (const SelfStressState& state : s.states)
    stateBytes += forcesBytes(state.elements);
  addList(
      s.states.size(), s.states.empty() ? 0 : stateBytes / s.states.size(),
      [&s](BufferedAppender& out) {
        appendField(out, "self_stress");
        out += "{\"count\": " + std::to_string(s.count) +
               ", \"mechanism_modes\": " + std::to_string(s.mechanismModes) +
               ", \"states_listed\": " + (s.statesListed ? "true" : "false") + ", \"states\": [";
      },
      [&s](BufferedAppender& out, size_t i) { appendForces(out, s.states[i].elements); },
      [&s](BufferedAppender& out) {
        out += "], \"taut_cables\": " + std::to_string(s.tautCables) +
               ", \"prestressable\": " + (s.prestressable ? "true" : "false") + ", \"prestress\": [";
      });
  addList(
      s.prestress.size(), s.prestress.empty() ? 0 : forcesBytes(s.prestress) / s.prestress.size(), {},
      [&s](BufferedAppender& out, size_t i) { appendForce(out, s.prestress[i]); },
      [&s](BufferedAppender& out) {
        out += ']';
        out += std::string(", \"prestress_stable\": ") + (s.prestressStable ? "true" : "false") +
               ", \"stability\": " + quote(s.stability) + "}";
        out += ",\n";
      });
}

/// The deployment, if any, the warnings and "}".
void JsonParts::addTail(const MobilityReport& r) {
  addFixed(256 + 64 * r.warnings.size(), [&r](BufferedAppender& out) {
    if (r.deployment)
      out += "  \"deployment\": " + deploymentJson(*r.deployment) + ",\n";
    appendField(out, "warnings");
    appendList(out, r.warnings, [&out](const std::string& text) { appendQuoted(out, text); });
    out += "\n}\n";
  });
}

JsonParts::Cut JsonParts::middle() const {
  size_t before = 0;
  for (size_t p = 0; p < parts_.size(); ++p) {
    const Part& part = parts_[p];
    const size_t bytes = part.fixedBytes + part.items * part.itemBytes;
    if (2 * (before + bytes) >= total_) {
      if (part.items == 0 || part.itemBytes == 0)
        return {p + 1, 0};
      const size_t wanted =
          (total_ / 2 > before + part.fixedBytes) ? total_ / 2 - before - part.fixedBytes : 0;
      return {p, std::min(part.items, wanted / part.itemBytes)};
    }
    before += bytes;
  }
  return end();
}

void JsonParts::write(std::string& text, Cut from, Cut to, std::ostream* stream) const {
  BufferedAppender out(text, stream);
  // A cut {p, 0} is before part p; a cut {p, i > 0} inside its list, after its opening and i items.
  const size_t endPart = std::min(parts_.size(), to.item > 0 ? to.part + 1 : to.part);
  for (size_t p = from.part; p < endPart; ++p) {
    const Part& part = parts_[p];
    const bool inside = p == from.part && from.item > 0;  // starts within the list: its opening is before
    const bool last = p == to.part;                       // ends within the list: its close is after
    writePart(out, part, p == from.part ? from.item : 0, last ? to.item : part.items, !inside, !last);
  }
}

void JsonParts::writeAll(std::string& text, size_t secondThreadFrom, std::ostream* stream) const {
  if (total_ < secondThreadFrom) {
    write(text, begin(), end(), stream);
    return;
  }
  const Cut cut = middle();
  core_detail::SideTask secondHalf(true, [&] {
    std::string half;
    half.reserve(total_ / 2 + total_ / 16);
    write(half, cut, end());
    return half;
  });
  write(text, begin(), cut, stream);
  const std::string half = secondHalf.get();
  if (stream != nullptr)
    stream->write(half.data(), static_cast<std::streamsize>(half.size()));
  else
    text += half;
}

void JsonParts::writePart(BufferedAppender& out, const Part& part, size_t from, size_t to, bool open,
                          bool close) const {
  if (open && part.open)
    part.open(out);
  for (size_t i = from; i < to; ++i) {
    if (i)
      out += ", ";
    part.item(out, i);
  }
  if (close && part.close)
    part.close(out);
}

}  // namespace

std::string toText(const MobilityReport& r) {
  std::ostringstream out;
  out << "Mechanism '" << r.robot << "' (" << r.file << "), " << r.mode << " analysis (lambda = " << r.lambda
      << ")\n";
  out << "  degrees of freedom (nullity of the constraint Jacobian): " << r.dof << "\n";
  out << "  Grubler-Kutzbach count:                                  " << r.grublerKutzbachDof << "\n";
  out << "  finite DOF (how it really moves near this pose):          " << r.finiteDof
      << (r.singular ? "  SINGULAR pose: the nullity counts first-order freedom the mechanism does not have"
                     : "")
      << "\n";
  out << "  passive DOF (idle groups) " << r.passiveDof << ", output DOF " << r.outputDof << "\n";
  for (const PassiveMotion& m : r.passiveMotions)
    out << "    passive: " << m.description << "\n";
  out << "  natural coordinates " << r.numCoordinates << ", constraint equations " << r.numConstraints
      << ", rank " << r.rank << "\n";
  out << "  Calladine-Maxwell: m = num_coordinates - rank = " << r.numCoordinates << " - " << r.rank << " = "
      << r.selfStress.mechanismModes
      << " (mechanism modes = dof), s = num_constraints - rank = " << r.numConstraints << " - " << r.rank
      << " = " << r.selfStress.count
      << " (states of self-stress); m - s = " << r.selfStress.mechanismModes - r.selfStress.count
      << " = num_coordinates - num_constraints\n";
  out << "  redundant equations: " << r.numRedundant << " (= dof - Grubler = " << r.dof - r.grublerKutzbachDof
      << ")\n";
  for (const RedundantJoint& j : r.redundantJoints) {
    out << "    joint " << j.name << ": " << j.redundantEquations << " of " << j.equations
        << " equations redundant\n";
  }
  for (const RedundantConstraint& c : r.redundantConstraints) {
    out << "      #" << c.index << " [" << c.source << " " << c.name << ", " << c.kind << "] " << c.equation
        << (c.cause == "configuration" ? "  (cause: configuration, only this pose makes it dependent)" : "")
        << "\n";
  }
  out << "  redundant links: ";
  if (!r.redundantLinksComputed) {
    out << "(not computed: the model is too large for the per-link search)";
  } else if (r.redundantLinks.empty()) {
    out << "none";
  }
  for (size_t i = 0; i < r.redundantLinks.size(); ++i)
    out << (i ? ", " : "") << r.redundantLinks[i];
  out << "\n  redundant boundary (ground) constraints: ";
  if (r.redundantBoundaries.empty())
    out << "none";
  for (size_t i = 0; i < r.redundantBoundaries.size(); ++i)
    out << (i ? ", " : "") << r.redundantBoundaries[i];
  out << "\n";
  std::vector<std::string> loop;
  for (const ElementStatus& s : r.links) {
    if (s.elementClass == ElementClass::OverConstrainedLoop)
      loop.push_back(s.name);
  }
  for (const ElementStatus& s : r.joints) {
    if (s.elementClass == ElementClass::OverConstrainedLoop)
      loop.push_back(s.name);
  }
  if (!loop.empty()) {
    out << "  other members of over-constrained loops: ";
    for (size_t i = 0; i < loop.size(); ++i)
      out << (i ? ", " : "") << loop[i];
    out << "\n";
  }
  for (const CableState& c : r.cables) {
    out << "  cable " << c.name << " (" << c.type << "): " << c.state << ", length " << number(c.length, 6)
        << " m, ends " << number(c.distance, 6) << " m apart\n";
  }
  if (r.deployment) {
    const DeploymentInfo& d = *r.deployment;
    out << "  deployment by cable " << d.cable << ": " << d.steps.size() << " steps, length "
        << number(d.initialLength, 6) << " m -> " << number(d.finalLength, 9) << " m, final DOF "
        << d.finalDof << "; " << d.reason << "\n";
  }
  const SelfStressInfo& s = r.selfStress;
  for (size_t k = 0; k < s.states.size() && k < 20; ++k) {
    out << "    state " << k + 1 << ":";
    for (size_t e = 0; e < s.states[k].elements.size() && e < 12; ++e)
      out << " " << s.states[k].elements[e].name << " " << number(s.states[k].elements[e].force, 3);
    if (s.states[k].elements.size() > 12)
      out << " ... (" << s.states[k].elements.size() << " elements)";
    out << "\n";
  }
  if (s.states.size() > 20 || !s.statesListed)
    out << "    ... (" << s.count << " states in all)\n";
  if (s.tautCables > 0) {
    out << "  prestress: " << (s.prestressable ? "prestressable" : "NOT prestressable") << " ("
        << s.tautCables << " taut cables)";
    if (s.prestressable)
      out << ", " << (s.prestressStable ? "prestress-stable" : "not prestress-stable");
    out << "; " << s.stability << "\n";
  }
  out << "  rank margin: smallest kept pivot " << number(r.rankMargin.smallestKeptPivot, 3)
      << ", largest dropped residual " << number(r.rankMargin.largestDroppedResidual, 3) << " (tolerance "
      << number(r.rankMargin.tolerance, 3) << ")"
      << (r.rankMargin.nearTolerance ? "  WARNING: near the tolerance" : "") << "\n";
  out << "  lengths in Lc = " << number(r.characteristicLength, 6) << " m; loop closure residual "
      << number(r.closureResidualBefore, 3) << " m before assembly, " << number(r.closureResidualAfter, 3)
      << " m after\n";
  // Where the mechanism is (driven joints exactly at their values) and how it got there.
  if (!r.positions.empty()) {
    constexpr size_t kShown = 12;
    out << "  positions reached [rad or m]:";
    for (size_t i = 0; i < r.positions.size() && i < kShown; ++i)
      out << (i ? ", " : " ") << r.positions[i].name << " " << number(r.positions[i].value, 9);
    if (r.positions.size() > kShown)
      out << ", ... (" << r.positions.size() - kShown << " more in --json)";
    out << "\n";
  }
  out << "  assembly: residual " << number(r.assembly.residual, 3) << " m, " << r.assembly.steps
      << " continuation steps, " << r.assembly.iterations << " iterations; events: ";
  if (r.assembly.events.empty())
    out << "none";
  for (size_t i = 0; i < r.assembly.events.size(); ++i)
    out << (i ? "; " : "") << r.assembly.events[i];
  out << "\n";
  return out.str();
}

std::optional<Diagnostic> checkReport(const MobilityReport& r) {
  auto refuse = [&](const std::string& what) {
    return makeDiagnostic(r.file, "report", r.robot, what + "; the report is not written");
  };
  auto finite = [&](double value, const std::string& field) -> std::optional<Diagnostic> {
    if (std::isfinite(value))
      return std::nullopt;
    return refuse(field + " is " + (std::isnan(value) ? "nan" : "inf"));
  };
  std::vector<std::pair<double, std::string>> numbers = {
      {r.characteristicLength, "characteristic_length"},
      {r.closureResidualBefore, "closure_residual.before"},
      {r.closureResidualAfter, "closure_residual.after"},
      {r.rankMargin.tolerance, "rank_margin.tolerance"},
      {r.rankMargin.smallestKeptPivot, "rank_margin.smallest_kept_pivot"},
      {r.rankMargin.largestDroppedResidual, "rank_margin.largest_dropped_residual"},
      {r.assembly.residual, "assembly.residual"}};
  for (const CableState& c : r.cables) {
    numbers.emplace_back(c.length, "cable " + c.name + " length");
    numbers.emplace_back(c.distance, "cable " + c.name + " distance");
  }
  for (const JointValue& p : r.positions)
    numbers.emplace_back(p.value, "position of " + p.name);
  for (const auto& [value, field] : numbers) {
    if (std::optional<Diagnostic> d = finite(value, field))
      return d;
  }
  if (!(r.characteristicLength > 0.0))
    return refuse("characteristic_length is not positive");
  if (r.rank < 0 || r.rank > r.numCoordinates || r.rank > r.numConstraints)
    return refuse("rank " + std::to_string(r.rank) +
                  " is outside [0, min(num_coordinates, num_constraints)]");
  if (r.numCoordinates - r.rank != r.dof) {
    return refuse("num_coordinates - rank = " + std::to_string(r.numCoordinates - r.rank) + " but dof is " +
                  std::to_string(r.dof));
  }
  if (r.numConstraints - r.rank != r.numRedundant ||
      static_cast<size_t>(r.numRedundant) != r.redundantConstraints.size()) {
    return refuse("num_redundant " + std::to_string(r.numRedundant) + ", redundant_constraints " +
                  std::to_string(r.redundantConstraints.size()) + " and num_constraints - rank " +
                  std::to_string(r.numConstraints - r.rank) + " differ");
  }
  if (r.finiteDof < 0 || r.passiveDof < 0 || r.outputDof != r.finiteDof - r.passiveDof)
    return refuse("finite_dof, passive_dof and output_dof are inconsistent");
  return std::nullopt;
}

Result<std::string> writeJson(const MobilityReport& report, bool sideThread) {
  if (std::optional<Diagnostic> d = checkReport(report))
    return *d;
  return toJson(report, sideThread);
}

std::optional<Diagnostic> writeJson(const MobilityReport& report, std::ostream& out, bool sideThread) {
  if (std::optional<Diagnostic> d = checkReport(report))
    return d;
  core_detail::writeJson(report, out, sideThread ? kJsonSideThreadBytes : std::numeric_limits<size_t>::max());
  return std::nullopt;
}

Result<std::string> writeText(const MobilityReport& report) {
  if (std::optional<Diagnostic> d = checkReport(report))
    return *d;
  return toText(report);
}

}  // namespace mobility_analysis
