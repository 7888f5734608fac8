#pragma once
/// @file JsonReader.h
/// The one JSON reading layer behind every loader (model.json, scenarios, patterns, breath styles,
/// anatomy and muscle gains). Parsing is bounded and strict: nesting deeper than a limit, numbers beyond
/// double range and duplicate keys are errors; every accessor checks the type and range of what it reads,
/// and every message names the source, the JSON path and at most a short excerpt of the offending value,
/// e.g. "calm.json: diaphragm_rr: unknown field (did you mean diaphragm_r?)".
/// The JSON library stays private to the sim library: this header only exposes std and Eigen types.

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

namespace pneuma::sim {

class JsonReader;
struct Range;

/// `s` cut to at most `maxChars` bytes at a character boundary, "..." marking the cut: how messages quote
/// strings that came from a file.
std::string excerptOf(const std::string& s, std::size_t maxChars = 60);

/// [bytes] largest file a loader reads (the default model.json is a few MB)
constexpr unsigned long long kMaxInputFileBytes = 256ull << 20;

/// The whole text of a file a loader reads (model, anatomy, gains, preset, scenario, pattern).
/// @throws Error "<path>: cannot open" (missing or unreadable), "<path>: not a regular file" (a directory, a
/// device
///         such as /dev/zero, a pipe) or "<path>: larger than 256 MiB"; `hint` is appended to the first.
std::string readInputFile(const std::string& path, const std::string& hint = "");

/// Limits applied while parsing.
struct JsonLimits {
  int maxDepth = 64;  ///< deepest allowed nesting of arrays and objects (the root object is depth 1)
};

/// A parsed JSON text that owns its values. Readers taken from it must not outlive it.
class JsonDocument {
 public:
  /// Parses `text`; `source` (usually the file name) prefixes every error message.
  /// @throws pneuma::sim::Error "<source>: invalid JSON at line L, column C: ..." for syntax errors, and
  ///         "<source>: <path>: ..." for nesting deeper than `limits.maxDepth`, a duplicate key or a number
  ///         beyond double range (e.g. 1e400).
  static JsonDocument parse(const std::string& text, const std::string& source, JsonLimits limits = {});

  JsonDocument(JsonDocument&&) noexcept;
  JsonDocument& operator=(JsonDocument&&) noexcept;
  ~JsonDocument();

  /// The root value, at the empty path.
  JsonReader root() const;

 private:
  struct Impl;
  explicit JsonDocument(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

/// A JSON value with its path ("overrides.gravity", "bodies[3].mass"); the accessors check the type and the
/// range and throw pneuma::sim::Error "<source>: <path>: <reason>, got <excerpt>" otherwise.
class JsonReader {
 public:
  /// Throws "<source>: <path>: <why>" (the path reads "(root)" at the top).
  [[noreturn]] void fail(const std::string& why) const;
  /// Rethrows a validation message "field: reason" about a child of this value with its full path.
  [[noreturn]] void failBelow(const std::string& fieldAndReason) const;
  const std::string& path() const { return m_path; }
  const std::string& source() const { return *m_source; }

  bool isObject() const;
  bool isArray() const;
  bool isString() const;
  bool isNumber() const;

  /// Rejects keys outside `allowed` (so that typos are not silently ignored), suggesting a close match.
  void allowKeys(std::initializer_list<const char*> allowed) const;
  /// The keys of an object, in document order; fails unless this is an object.
  std::vector<std::string> keys() const;
  /// Whether this is an object with member `key`.
  bool has(const std::string& key) const;
  /// The member `key`; fails with "must be an object" or "<path>.<key>: missing".
  JsonReader at(const std::string& key) const;
  /// The number of elements of an array; fails unless this is an array.
  std::size_t size() const;
  /// Element `i` of an array (i < size()).
  JsonReader operator[](std::size_t i) const;

  /// A finite number.
  double number() const;
  /// A number > 0.
  double positive() const;
  /// A number >= 0.
  double nonNegative() const;
  /// A number in [lo, hi].
  double numberIn(double lo, double hi) const;
  /// A number inside one of the run limits of Limits.h ("must be in [1e-06, 0.05] s, got 1e-300").
  double numberIn(const Range& range) const;
  /// A number in (0, hi].
  double positiveAtMost(double hi) const;
  /// An integer (no fraction, no exponent) in [lo, hi]; 4294967297 is not 1.
  std::int64_t integerIn(std::int64_t lo, std::int64_t hi) const;
  /// An integer in the range of int.
  int integer() const;
  /// A non-negative integer up to 2^64 - 1.
  std::uint64_t unsignedInteger() const;
  bool boolean() const;
  std::string string() const;
  /// An array of 3 numbers.
  Eigen::Vector3d vec3() const;
  /// An array of 3 integers in the range of int.
  Eigen::Vector3i index3() const;
  /// number() of member `key`, or `fallback` when absent.
  double numberOr(const std::string& key, double fallback) const;
  /// string() of member `key`, or `fallback` when absent.
  std::string stringOr(const std::string& key, const std::string& fallback) const;

  /// Checks a versioned file's header: member "format" equal to `format` and "version" equal to `version`;
  /// fails with 'must be "<format>"' or "unsupported version V (this build reads N)".
  void checkHeader(const char* format, int version) const;

  /// The value as JSON text (for values passed on to another parser, e.g. an inline pattern).
  std::string dump(int indent = -1) const;
  /// At most `maxChars` characters of the value as JSON text, "..." marking a cut; cheap on huge values.
  std::string excerpt(std::size_t maxChars = 60) const;

 private:
  friend class JsonDocument;
  JsonReader(const void* node, std::string path, const std::string* source)
      : m_node(node), m_path(std::move(path)), m_source(source) {}
  std::string join(const std::string& key) const { return m_path.empty() ? key : m_path + "." + key; }

  const void* m_node;  // the nlohmann::json value (kept out of this header)
  std::string m_path;
  const std::string* m_source;
};

}  // namespace pneuma::sim
