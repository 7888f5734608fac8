#include "pneuma/sim/Checkpoint.h"

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>

#include "pneuma/sim/Error.h"

namespace pneuma::sim {

namespace {

std::size_t at(int i) { return static_cast<std::size_t>(i); }

// C99 %a: exact for every finite double; inf and nan as words
std::string hexDouble(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%a", v);
  return buffer;
}

}  // namespace

// ---- writer

void CheckpointWriter::write(const std::string& key, double value) {
  m_out << key << ' ' << hexDouble(value) << '\n';
}

void CheckpointWriter::write(const std::string& key, long long value) {
  m_out << key << ' ' << value << '\n';
}

void CheckpointWriter::write(const std::string& key, std::uint64_t value) {
  m_out << key << ' ' << value << '\n';
}

void CheckpointWriter::write(const std::string& key, const std::string& value) {
  m_out << key << ' ' << value.size() << ' ' << value << '\n';
}

void CheckpointWriter::beginArray(const std::string& key, Eigen::Index rows, Eigen::Index cols) {
  m_out << key << ' ' << rows << ' ' << cols;
}

void CheckpointWriter::scalar(double v) { m_out << ' ' << hexDouble(v); }

void CheckpointWriter::scalar(int v) { m_out << ' ' << v; }

void CheckpointWriter::endLine() { m_out << '\n'; }

// ---- reader

void CheckpointReader::fail(const std::string& key, const std::string& what) const {
  throw Error(m_source + ": checkpoint field '" + key + "': " + what);
}

std::string CheckpointReader::token(const std::string& key) {
  std::string t;
  if (!(m_in >> t)) fail(key, "the file ends here");
  return t;
}

void CheckpointReader::expectKey(const std::string& key) {
  const std::string found = token(key);
  if (found != key) fail(key, "found '" + found.substr(0, 60) + "' instead");
}

double CheckpointReader::readDouble(const std::string& key) {
  expectKey(key);
  double v = 0.0;
  scalar(key, v);
  return v;
}

long long CheckpointReader::readInt(const std::string& key) {
  expectKey(key);
  const std::string t = token(key);
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(t.c_str(), &end, 10);
  if (end == t.c_str() || *end != '\0' || errno != 0) fail(key, "not an integer: '" + t.substr(0, 60) + "'");
  return v;
}

std::uint64_t CheckpointReader::readUnsigned(const std::string& key) {
  expectKey(key);
  const std::string t = token(key);
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(t.c_str(), &end, 10);
  if (end == t.c_str() || *end != '\0' || errno != 0 || t[0] == '-')
    fail(key, "not an unsigned integer: '" + t.substr(0, 60) + "'");
  return static_cast<std::uint64_t>(v);
}

std::string CheckpointReader::readString(const std::string& key) {
  const long long n = readInt(key);
  if (n < 0 || n > (1 << 20)) fail(key, "bad string length " + std::to_string(n));
  if (m_in.get() != ' ') fail(key, "no space before the string");
  std::string s(static_cast<std::size_t>(n), '\0');
  if (n > 0 && !m_in.read(s.data(), n)) fail(key, "the file ends inside the string");
  return s;
}

std::pair<Eigen::Index, Eigen::Index> CheckpointReader::beginArray(const std::string& key) {
  expectKey(key);
  long long rows = -1, cols = -1;
  if (!(m_in >> rows >> cols) || rows < 0 || cols < 0 || (cols > 0 && rows > (1LL << 28) / cols))
    fail(key, "bad array shape");
  return {static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols)};
}

void CheckpointReader::scalar(const std::string& key, double& v) {
  const std::string t = token(key);
  char* end = nullptr;
  v = std::strtod(t.c_str(), &end);  // reads %a exactly, and inf / nan
  if (end == t.c_str() || *end != '\0') fail(key, "not a number: '" + t.substr(0, 60) + "'");
}

void CheckpointReader::scalar(const std::string& key, int& v) {
  const std::string t = token(key);
  errno = 0;
  char* end = nullptr;
  const long n = std::strtol(t.c_str(), &end, 10);
  if (end == t.c_str() || *end != '\0' || errno != 0 || n < INT32_MIN || n > INT32_MAX)
    fail(key, "not an integer: '" + t.substr(0, 60) + "'");
  v = static_cast<int>(n);
}

// ---- the sim's records

void writeState(CheckpointWriter& out, const State& s) {
  out.write("state.time", s.time);
  out.write("state.steps", s.steps);
  Eigen::Matrix4Xd q(4, static_cast<Eigen::Index>(s.bodyOrientation.size()));
  for (std::size_t b = 0; b < s.bodyOrientation.size(); ++b)
    q.col(static_cast<Eigen::Index>(b)) = s.bodyOrientation[b].coeffs();
  out.write("state.bodyPosition", s.bodyPosition);
  out.write("state.bodyOrientation", q);
  out.write("state.bodyVelocity", s.bodyVelocity);
  out.write("state.bodyAngularVelocity", s.bodyAngularVelocity);
  out.write("state.nodePosition", s.nodePosition);
  out.write("state.nodeVelocity", s.nodeVelocity);
}

State readState(CheckpointReader& in, const Model& model) {
  const Eigen::Index nb = model.bodies.size(), nn = model.nodes.size();
  State s;
  s.time = in.readDouble("state.time");
  s.steps = in.readInt("state.steps");
  Eigen::Matrix4Xd q;
  in.readSized("state.bodyPosition", s.bodyPosition, 3, nb);
  in.readSized("state.bodyOrientation", q, 4, nb);
  s.bodyOrientation.resize(static_cast<std::size_t>(nb));
  for (Eigen::Index b = 0; b < nb; ++b) s.bodyOrientation[static_cast<std::size_t>(b)].coeffs() = q.col(b);
  in.readSized("state.bodyVelocity", s.bodyVelocity, 3, nb);
  in.readSized("state.bodyAngularVelocity", s.bodyAngularVelocity, 3, nb);
  in.readSized("state.nodePosition", s.nodePosition, 3, nn);
  in.readSized("state.nodeVelocity", s.nodeVelocity, 3, nn);
  return s;
}

void writeSolverMemory(CheckpointWriter& out, const SolverMemory& m) {
  out.write("solver.hasFactorization", m.hasFactorization);
  // the values of A0 by slot: factoring them again gives the factorization's bits (BlockLdlt::factorize() is
  // a function of the values and the analysis)
  const int slots = m.hasFactorization ? m.system.valueBlocks() : 0;
  Eigen::Matrix<double, 9, Eigen::Dynamic> values(9, slots);
  for (int k = 0; k < slots; ++k)
    values.col(k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(m.system.value(k).data());
  out.write("solver.systemValues", values);
  out.write("solver.rankOne", m.rankOne);
  out.write("solver.rankOneSolve", m.rankOneSolve);
  out.write("solver.rankOneScale", m.rankOneScale);
  out.write("solver.rankTwo", m.rankTwo);
  out.write("solver.rankTwoSolve", m.rankTwoSolve);
  out.write("solver.rankTwoScale", m.rankTwoScale);
  out.write("solver.factorDt", m.factorDt);
  out.write("solver.factorAxial", m.factorAxial);
  out.write("solver.factorTransverse", m.factorTransverse);
  out.write("solver.factorDirection", m.factorDirection);
  out.write("solver.factorAge", m.factorAge);
  out.write("solver.cgIterations", m.cgIterations);
}

void readSolverMemory(CheckpointReader& in, SolverMemory& m) {
  m.hasFactorization = in.readBool("solver.hasFactorization");
  Eigen::Matrix<double, 9, Eigen::Dynamic> values;
  in.readSized("solver.systemValues", values, 9, m.hasFactorization ? m.system.valueBlocks() : 0);
  m.system.clearValues();
  if (m.hasFactorization) {
    for (int k = 0; k < m.system.valueBlocks(); ++k)
      Eigen::Map<Eigen::Matrix<double, 9, 1>>(m.system.value(k).data()) = values.col(k);
    if (!m.system.factorize()) in.fail("solver.systemValues", "the stored matrix is not positive definite");
  }
  in.read("solver.rankOne", m.rankOne);
  in.read("solver.rankOneSolve", m.rankOneSolve);
  m.rankOneScale = in.readDouble("solver.rankOneScale");
  in.read("solver.rankTwo", m.rankTwo);
  in.read("solver.rankTwoSolve", m.rankTwoSolve);
  m.rankTwoScale = in.readDouble("solver.rankTwoScale");
  m.factorDt = in.readDouble("solver.factorDt");
  in.read("solver.factorAxial", m.factorAxial);
  in.read("solver.factorTransverse", m.factorTransverse);
  in.read("solver.factorDirection", m.factorDirection);
  m.factorAge = static_cast<int>(in.readInt("solver.factorAge"));
  m.cgIterations = static_cast<int>(in.readInt("solver.cgIterations"));
  const Eigen::Index nf = 3 * static_cast<Eigen::Index>(m.system.blocks());
  const bool fits = m.rankOne.size() == nf && m.rankOneSolve.size() == nf &&
                    (m.rankTwo.size() == 0 || (m.rankTwo.size() == nf && m.rankTwoSolve.size() == nf));
  if (m.hasFactorization && !fits)
    in.fail("solver.rankOne", "sizes do not match the model's free coordinates");
}

void writeStepOutputs(CheckpointWriter& out, const StepOutputs& o) {
  out.write("outputs.elementForce", o.elementForce);
  out.write("outputs.elementLength", o.elementLength);
  out.write("outputs.gutVolume", o.gutVolume);
  out.write("outputs.gutPressure", o.gutPressure);
  out.write("outputs.pleuralPressure", o.pleuralPressure);
  out.write("outputs.maxJointError", o.maxJointError);
}

void readStepOutputs(CheckpointReader& in, StepOutputs& o) {
  const Eigen::Index ne = o.elementForce.size();
  in.readSized("outputs.elementForce", o.elementForce, ne, 1);
  in.readSized("outputs.elementLength", o.elementLength, ne, 1);
  o.gutVolume = in.readDouble("outputs.gutVolume");
  o.gutPressure = in.readDouble("outputs.gutPressure");
  o.pleuralPressure = in.readDouble("outputs.pleuralPressure");
  o.maxJointError = in.readDouble("outputs.maxJointError");
}

void writeActivations(CheckpointWriter& out, const std::string& key, const Activations& a) {
  Eigen::Matrix2Xd m(2, kElementGroupCount);
  for (int g = 0; g < kElementGroupCount; ++g) m.col(g) << a[at(g)].r, a[at(g)].alpha;
  out.write(key, m);
}

Activations readActivations(CheckpointReader& in, const std::string& key) {
  Eigen::Matrix2Xd m;
  in.readSized(key, m, 2, kElementGroupCount);
  Activations a{};
  for (int g = 0; g < kElementGroupCount; ++g) a[at(g)] = {m(0, g), m(1, g)};
  return a;
}

void writeMetrics(CheckpointWriter& out, const Metrics& m) {
  out.write("metrics.time", m.time);
  out.write("metrics.lungVolume", m.lungVolume);
  out.write("metrics.gutVolume", m.gutVolume);
  out.write("metrics.gutVolumeError", m.gutVolumeError);
  out.write("metrics.gutPressure", m.gutPressure);
  out.write("metrics.abdomenVolume", m.abdomenVolume);
  out.write("metrics.elementForce", m.elementForce);
  Eigen::VectorXi slack(static_cast<Eigen::Index>(m.isSlack.size()));
  for (std::size_t e = 0; e < m.isSlack.size(); ++e) slack(static_cast<Eigen::Index>(e)) = m.isSlack[e];
  out.write("metrics.isSlack", slack);
  out.write("metrics.groupMeanTension",
            Eigen::Map<const Eigen::VectorXd>(m.groupMeanTension.data(), kElementGroupCount));
  writeActivations(out, "metrics.activations", m.activations);
  out.write("metrics.kineticEnergy", m.kineticEnergy);
  out.write("metrics.elasticEnergy", m.elasticEnergy);
  out.write("metrics.gravityEnergy", m.gravityEnergy);
  out.write("metrics.maxJointError", m.maxJointError);
  out.write("metrics.landmarks", m.landmarks);
}

void readMetrics(CheckpointReader& in, Metrics& m) {
  m.time = in.readDouble("metrics.time");
  m.lungVolume = in.readDouble("metrics.lungVolume");
  m.gutVolume = in.readDouble("metrics.gutVolume");
  m.gutVolumeError = in.readDouble("metrics.gutVolumeError");
  m.gutPressure = in.readDouble("metrics.gutPressure");
  m.abdomenVolume = in.readDouble("metrics.abdomenVolume");
  in.read("metrics.elementForce", m.elementForce);
  Eigen::VectorXi slack;
  in.read("metrics.isSlack", slack);
  m.isSlack.assign(static_cast<std::size_t>(slack.size()), 0);
  for (Eigen::Index e = 0; e < slack.size(); ++e)
    m.isSlack[static_cast<std::size_t>(e)] = static_cast<std::uint8_t>(slack(e));
  Eigen::VectorXd tension;
  in.readSized("metrics.groupMeanTension", tension, kElementGroupCount, 1);
  for (int g = 0; g < kElementGroupCount; ++g) m.groupMeanTension[at(g)] = tension(g);
  m.activations = readActivations(in, "metrics.activations");
  m.kineticEnergy = in.readDouble("metrics.kineticEnergy");
  m.elasticEnergy = in.readDouble("metrics.elasticEnergy");
  m.gravityEnergy = in.readDouble("metrics.gravityEnergy");
  m.maxJointError = in.readDouble("metrics.maxJointError");
  in.read("metrics.landmarks", m.landmarks);
}

}  // namespace pneuma::sim
