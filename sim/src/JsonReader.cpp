#include "pneuma/sim/JsonReader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/Limits.h"

namespace pneuma::sim {

using nlohmann::json;

std::string readInputFile(const std::string& path, const std::string& hint) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) throw Error(path + ": cannot open" + hint);
  if (!std::filesystem::is_regular_file(st)) throw Error(path + ": not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(path + ": cannot open" + hint);
  if (size > kMaxInputFileBytes)
    throw Error(path + ": larger than 256 MiB (" + std::to_string(size) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open" + hint);
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) throw Error(path + ": cannot read the whole file");
  return text;
}

std::string excerptOf(const std::string& s, std::size_t maxChars) {
  if (s.size() <= maxChars) return s;
  // back up to the first byte of a UTF-8 character
  std::size_t n = maxChars > 3 ? maxChars - 3 : 0;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return s.substr(0, n) + "...";
}

namespace {

const json& node(const void* p) { return *static_cast<const json*>(p); }

std::string quoted(const std::string& s, std::size_t maxChars) {
  // dump a prefix only, so that a huge string costs no more than its excerpt
  return json(s.substr(0, maxChars + 1)).dump(-1, ' ', false, json::error_handler_t::replace);
}

// appends v as JSON text, stopping once `out` holds more than `limit` characters
void writeBounded(const json& v, std::string& out, std::size_t limit) {
  if (out.size() > limit) return;
  switch (v.type()) {
    case json::value_t::object: {
      out += '{';
      bool first = true;
      for (auto it = v.begin(); it != v.end() && out.size() <= limit; ++it) {
        if (!first) out += ", ";
        first = false;
        out += quoted(it.key(), limit) + ": ";
        writeBounded(it.value(), out, limit);
      }
      out += '}';
      return;
    }
    case json::value_t::array: {
      out += '[';
      for (std::size_t i = 0; i < v.size() && out.size() <= limit; ++i) {
        if (i > 0) out += ", ";
        writeBounded(v[i], out, limit);
      }
      out += ']';
      return;
    }
    case json::value_t::string:
      out += quoted(v.get_ref<const std::string&>(), limit);
      return;
    default:
      out += v.dump();
      return;
  }
}

// the classic edit distance, for "did you mean" suggestions
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// where the parser is in the document: one frame per open array or object, for paths, duplicate keys and
// depth
class ParsePosition {
 public:
  ParsePosition(const std::string& source, int maxDepth) : m_source(source), m_maxDepth(maxDepth) {}

  bool onEvent(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (static_cast<int>(m_frames.size()) >= m_maxDepth)
          fail("nesting deeper than " + std::to_string(m_maxDepth) + " levels");
        m_frames.push_back({event == json::parse_event_t::array_start, 0, {}, {}});
        break;
      case json::parse_event_t::key: {
        Frame& f = m_frames.back();
        f.key = parsed.get<std::string>();
        if (!f.seen.insert(f.key).second) fail("duplicate key");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        m_frames.pop_back();
        advance();
        break;
      case json::parse_event_t::value:
        advance();
        break;
    }
    return true;
  }

  // the path of the value being read, e.g. "bodies[2].mass"
  std::string path() const {
    std::string p;
    for (const Frame& f : m_frames) {
      if (f.isArray)
        p += "[" + std::to_string(f.index) + "]";
      else if (!f.key.empty() || !f.seen.empty())
        p += (p.empty() ? "" : ".") + excerptOf(f.key, 60);
    }
    return p.empty() ? "(root)" : excerptOf(p, 120);  // deep nesting makes long paths
  }

  [[noreturn]] void fail(const std::string& why) const { throw Error(m_source + ": " + path() + ": " + why); }

 private:
  struct Frame {
    bool isArray;
    std::size_t index;  // arrays: elements read so far
    std::string key;    // objects: the current key
    std::set<std::string> seen;
  };
  void advance() {
    if (!m_frames.empty() && m_frames.back().isArray) ++m_frames.back().index;
  }

  const std::string& m_source;
  int m_maxDepth;
  std::vector<Frame> m_frames;
};

// nlohmann's parse error without its tag, the bytes it quotes cut short
std::string parseErrorText(const json::parse_error& e) {
  std::string what = e.what();
  const std::string tag = "parse error";
  const std::size_t at = what.find(tag);
  if (at != std::string::npos) what = what.substr(at + tag.size());
  const std::string lastRead = "last read: '";
  const std::size_t from = what.find(lastRead);
  if (from != std::string::npos) {
    const std::size_t start = from + lastRead.size();
    const std::size_t end = what.find("'; ", start);
    const std::size_t len = (end == std::string::npos ? what.size() : end) - start;
    what.replace(start, len, excerptOf(what.substr(start, len), 60));
  }
  return "invalid JSON" + what;
}

}  // namespace

// =============================================================================================

struct JsonDocument::Impl {
  std::string source;
  json doc;
};

JsonDocument::JsonDocument(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
JsonDocument::JsonDocument(JsonDocument&&) noexcept = default;
JsonDocument& JsonDocument::operator=(JsonDocument&&) noexcept = default;
JsonDocument::~JsonDocument() = default;

JsonDocument JsonDocument::parse(const std::string& text, const std::string& source, JsonLimits limits) {
  auto impl = std::make_unique<Impl>();
  impl->source = source;
  ParsePosition pos(impl->source, limits.maxDepth);
  try {
    impl->doc = json::parse(
        text, [&pos](int, json::parse_event_t event, json& parsed) { return pos.onEvent(event, parsed); });
  } catch (const json::parse_error& e) {
    throw Error(source + ": " + parseErrorText(e));
  } catch (const json::out_of_range& e) {
    // 406: a number literal beyond double range; the position still points at it
    if (e.id == 406) {
      const std::string what = e.what();
      const std::size_t q = what.find('\'');
      const std::string literal = q == std::string::npos ? "" : what.substr(q + 1, what.rfind('\'') - q - 1);
      pos.fail("number " + excerptOf(literal, 60) + " is beyond the range of a double");
    }
    pos.fail(std::string("invalid JSON: ") + excerptOf(e.what(), 120));
  } catch (const json::exception& e) {
    pos.fail(std::string("invalid JSON: ") + excerptOf(e.what(), 120));
  }
  return JsonDocument(std::move(impl));
}

JsonReader JsonDocument::root() const { return JsonReader(&m_impl->doc, "", &m_impl->source); }

// =============================================================================================

void JsonReader::fail(const std::string& why) const {
  throw Error(*m_source + ": " + (m_path.empty() ? std::string("(root)") : m_path) + ": " + why);
}

void JsonReader::checkHeader(const char* format, int version) const {
  if (at("format").string() != format) at("format").fail(std::string("must be \"") + format + "\"");
  const JsonReader v = at("version");
  if (v.integerIn(0, std::numeric_limits<int>::max()) != version)
    v.fail("unsupported version " + v.excerpt() + " (this build reads " + std::to_string(version) + ")");
}

void JsonReader::failBelow(const std::string& fieldAndReason) const {
  throw Error(*m_source + ": " + (m_path.empty() ? "" : m_path + ".") + fieldAndReason);
}

bool JsonReader::isObject() const { return node(m_node).is_object(); }
bool JsonReader::isArray() const { return node(m_node).is_array(); }
bool JsonReader::isString() const { return node(m_node).is_string(); }
bool JsonReader::isNumber() const { return node(m_node).is_number(); }

void JsonReader::allowKeys(std::initializer_list<const char*> allowed) const {
  const json& j = node(m_node);
  if (!j.is_object()) fail("must be an object, got " + excerpt());
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (std::any_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; })) continue;
    // suggest the closest allowed key when it is only a typo away
    std::string best;
    std::size_t bestDistance = 3;
    for (const char* k : allowed) {
      const std::size_t d = editDistance(it.key(), k);
      if (d < bestDistance) bestDistance = d, best = k;
    }
    JsonReader(m_node, join(excerptOf(it.key(), 60)), m_source)
        .fail(best.empty() ? "unknown field" : "unknown field (did you mean " + best + "?)");
  }
}

std::vector<std::string> JsonReader::keys() const {
  const json& j = node(m_node);
  if (!j.is_object()) fail("must be an object, got " + excerpt());
  std::vector<std::string> out;
  for (auto it = j.begin(); it != j.end(); ++it) out.push_back(it.key());
  return out;
}

bool JsonReader::has(const std::string& key) const {
  const json& j = node(m_node);
  return j.is_object() && j.contains(key);
}

JsonReader JsonReader::at(const std::string& key) const {
  const json& j = node(m_node);
  if (!j.is_object()) fail("must be an object, got " + excerpt());
  auto it = j.find(key);
  if (it == j.end()) JsonReader(m_node, join(key), m_source).fail("missing");
  return JsonReader(&*it, join(excerptOf(key)), m_source);
}

std::size_t JsonReader::size() const {
  const json& j = node(m_node);
  if (!j.is_array()) fail("must be an array, got " + excerpt());
  return j.size();
}

JsonReader JsonReader::operator[](std::size_t i) const {
  return JsonReader(&node(m_node).at(i), m_path + "[" + std::to_string(i) + "]", m_source);
}

double JsonReader::number() const {
  const json& j = node(m_node);
  if (!j.is_number()) fail("must be a number, got " + excerpt());
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail("must be finite");
  return v;
}

double JsonReader::positive() const {
  const double v = number();
  if (v <= 0.0) fail("must be > 0, got " + excerpt());
  return v;
}

double JsonReader::nonNegative() const {
  const double v = number();
  if (v < 0.0) fail("must be >= 0, got " + excerpt());
  return v;
}

double JsonReader::numberIn(const Range& range) const {
  const double v = number();
  if (!range.contains(v)) fail(range.problem(v));
  return v;
}

double JsonReader::numberIn(double lo, double hi) const {
  const double v = number();
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "must be in [" << lo << ", " << hi << "], got " << excerpt();
    fail(s.str());
  }
  return v;
}

double JsonReader::positiveAtMost(double hi) const {
  const double v = positive();
  if (v > hi) {
    std::ostringstream s;
    s << "must be in (0, " << hi << "], got " << excerpt();
    fail(s.str());
  }
  return v;
}

std::int64_t JsonReader::integerIn(std::int64_t lo, std::int64_t hi) const {
  const json& j = node(m_node);
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!j.is_number_integer()) fail("must be an integer in " + range + ", got " + excerpt());
  // unsigned values above the int64 range are out of any int64 range
  const bool fits =
      j.is_number_unsigned()
          ? j.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) &&
                static_cast<std::int64_t>(j.get<std::uint64_t>()) <= hi &&
                static_cast<std::int64_t>(j.get<std::uint64_t>()) >= lo
          : j.get<std::int64_t>() >= lo && j.get<std::int64_t>() <= hi;
  if (!fits) fail("must be an integer in " + range + ", got " + excerpt());
  return j.get<std::int64_t>();
}

int JsonReader::integer() const {
  return static_cast<int>(integerIn(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
}

std::uint64_t JsonReader::unsignedInteger() const {
  const json& j = node(m_node);
  if (!j.is_number_unsigned()) fail("must be a non-negative integer, got " + excerpt());
  return j.get<std::uint64_t>();
}

bool JsonReader::boolean() const {
  const json& j = node(m_node);
  if (!j.is_boolean()) fail("must be true or false, got " + excerpt());
  return j.get<bool>();
}

std::string JsonReader::string() const {
  const json& j = node(m_node);
  if (!j.is_string()) fail("must be a string, got " + excerpt());
  return j.get<std::string>();
}

Eigen::Vector3d JsonReader::vec3() const {
  if (!isArray() || node(m_node).size() != 3) fail("must be an array of 3 numbers, got " + excerpt());
  return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
}

Eigen::Vector3i JsonReader::index3() const {
  if (!isArray() || node(m_node).size() != 3) fail("must be an array of 3 integers, got " + excerpt());
  return {(*this)[0].integer(), (*this)[1].integer(), (*this)[2].integer()};
}

double JsonReader::numberOr(const std::string& key, double fallback) const {
  return has(key) ? at(key).number() : fallback;
}

std::string JsonReader::stringOr(const std::string& key, const std::string& fallback) const {
  return has(key) ? at(key).string() : fallback;
}

std::string JsonReader::dump(int indent) const {
  return node(m_node).dump(indent, ' ', false, json::error_handler_t::replace);
}

std::string JsonReader::excerpt(std::size_t maxChars) const {
  std::string out;
  writeBounded(node(m_node), out, maxChars);
  return excerptOf(std::move(out), maxChars);
}

}  // namespace pneuma::sim
