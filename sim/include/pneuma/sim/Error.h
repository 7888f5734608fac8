#pragma once
/// @file Error.h
/// The one exception type the sim layer throws for bad input and numerical failure.

#include <stdexcept>
#include <string>

namespace pneuma::sim {

/// Raised for invalid models, out-of-range parameters and simulation blow-ups. The message always
/// names the offending field, element, body or value (e.g. "elements[12].restLength: must be > 0, got 0").
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// Raised by a long preparation (the pattern drive's calibration) that stopped because its stop flag was
/// raised (Ctrl-C): nothing is wrong with the input, the caller asked to stop.
class Interrupted : public Error {
 public:
  explicit Interrupted(const std::string& what) : Error(what) {}
};

}  // namespace pneuma::sim
