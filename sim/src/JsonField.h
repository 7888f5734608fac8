#pragma once
// JsonField: a JSON value together with its path, so that every parse error names the file and the
// field ("scenario.json: overrides.gravity: must be true or false"). Internal to sim/src; the one
// reader behind model.json, scenario files and pattern files.

#include "pneuma/sim/Error.h"

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>

namespace pneuma::sim::detail {

class JsonField {
 public:
  JsonField(const nlohmann::json& j, std::string path, const std::string& source)
      : m_j(j), m_path(std::move(path)), m_source(source) {}

  [[noreturn]] void fail(const std::string& why) const {
    throw Error(m_source + ": " + (m_path.empty() ? std::string("(root)") : m_path) + ": " + why);
  }
  // rethrows a validation message "field: reason" about a child of this value with its full path
  [[noreturn]] void failBelow(const std::string& fieldAndReason) const {
    throw Error(m_source + ": " + (m_path.empty() ? "" : m_path + ".") + fieldAndReason);
  }
  const std::string& path() const { return m_path; }
  const nlohmann::json& raw() const { return m_j; }

  // rejects keys outside `allowed`, so that typos are not silently ignored
  void allowKeys(std::initializer_list<const char*> allowed) const {
    if (!m_j.is_object()) fail("must be an object");
    for (auto it = m_j.begin(); it != m_j.end(); ++it) {
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; }))
        child(it.key()).fail("unknown field");
    }
  }
  bool has(const std::string& key) const { return m_j.is_object() && m_j.contains(key); }
  // the member `key` (which must exist)
  JsonField child(const std::string& key) const { return JsonField(m_j.at(key), join(key), m_source); }
  // the member `key`; fails with "missing" when absent
  JsonField at(const std::string& key) const {
    if (!m_j.is_object()) fail("must be an object");
    if (!m_j.contains(key)) JsonField(m_j, join(key), m_source).fail("missing");
    return child(key);
  }

  std::size_t size() const {
    if (!m_j.is_array()) fail("must be an array");
    return m_j.size();
  }
  JsonField operator[](std::size_t i) const {
    return JsonField(m_j.at(i), m_path + "[" + std::to_string(i) + "]", m_source);
  }

  double number() const {
    if (!m_j.is_number()) fail("must be a number, got " + m_j.dump());
    const double v = m_j.get<double>();
    if (!std::isfinite(v)) fail("must be finite");
    return v;
  }
  double positive() const {
    const double v = number();
    if (v <= 0.0) fail("must be > 0, got " + m_j.dump());
    return v;
  }
  double nonNegative() const {
    const double v = number();
    if (v < 0.0) fail("must be >= 0, got " + m_j.dump());
    return v;
  }
  int integer() const {
    if (!m_j.is_number_integer()) fail("must be an integer, got " + m_j.dump());
    return m_j.get<int>();
  }
  bool boolean() const {
    if (!m_j.is_boolean()) fail("must be true or false, got " + m_j.dump());
    return m_j.get<bool>();
  }
  std::string string() const {
    if (!m_j.is_string()) fail("must be a string, got " + m_j.dump());
    return m_j.get<std::string>();
  }
  Eigen::Vector3d vec3() const {
    if (!m_j.is_array() || m_j.size() != 3) fail("must be an array of 3 numbers");
    return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
  }
  Eigen::Vector3i index3() const {
    if (!m_j.is_array() || m_j.size() != 3) fail("must be an array of 3 integers");
    return {(*this)[0].integer(), (*this)[1].integer(), (*this)[2].integer()};
  }
  double numberOr(const std::string& key, double fallback) const { return has(key) ? at(key).number() : fallback; }
  std::string stringOr(const std::string& key, const std::string& fallback) const {
    return has(key) ? at(key).string() : fallback;
  }

 private:
  std::string join(const std::string& key) const { return m_path.empty() ? key : m_path + "." + key; }

  const nlohmann::json& m_j;
  std::string m_path;
  const std::string& m_source;
};

}  // namespace pneuma::sim::detail
