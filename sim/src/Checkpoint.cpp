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

void CheckpointReader::field(const std::string& key, int& v) {
  const long long n = readInt(key);
  if (n < INT32_MIN || n > INT32_MAX) fail(key, "integer out of range: " + std::to_string(n));
  v = static_cast<int>(n);
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
  if (!(m_in >> rows >> cols) || rows < 0 || cols < 0 || (cols > 0 && rows > (1LL << 26) / cols))
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

// ---- the sim's records: one list of fields per record, walked by the writer (const records) and the reader

namespace {

template <typename Archive, typename S>
void stateFields(Archive& a, S& s, Eigen::Matrix4Xd& orientation, Eigen::Index nb, Eigen::Index nn) {
  a.field("state.time", s.time);
  a.field("state.steps", s.steps);
  a.field("state.bodyPosition", s.bodyPosition, 3, nb);
  a.field("state.bodyOrientation", orientation, 4, nb);  // quaternion coefficients x, y, z, w
  a.field("state.bodyVelocity", s.bodyVelocity, 3, nb);
  a.field("state.bodyAngularVelocity", s.bodyAngularVelocity, 3, nb);
  a.field("state.nodePosition", s.nodePosition, 3, nn);
  a.field("state.nodeVelocity", s.nodeVelocity, 3, nn);
}

// `values`: the values of A0 by slot, 9 per 3 x 3 block (none without a factorization)
template <typename Archive, typename M>
void solverFields(Archive& a, M& m, Eigen::Matrix<double, 9, Eigen::Dynamic>& values) {
  a.field("solver.hasFactorization", m.hasFactorization);
  a.field("solver.systemValues", values, 9, m.hasFactorization ? m.system.valueBlocks() : 0);
  a.field("solver.rankOne", m.rankOne);
  a.field("solver.rankOneSolve", m.rankOneSolve);
  a.field("solver.rankOneScale", m.rankOneScale);
  a.field("solver.rankTwo", m.rankTwo);
  a.field("solver.rankTwoSolve", m.rankTwoSolve);
  a.field("solver.rankTwoScale", m.rankTwoScale);
  a.field("solver.volumeRank", m.volumeRank);
  a.field("solver.volumeRankSolve", m.volumeRankSolve);
  a.field("solver.volumeRankScale", m.volumeRankScale);
  a.field("solver.factorDt", m.factorDt);
  a.field("solver.factorAxial", m.factorAxial);
  a.field("solver.factorTransverse", m.factorTransverse);
  a.field("solver.factorDirection", m.factorDirection);
  a.field("solver.factorAge", m.factorAge);
  a.field("solver.cgIterations", m.cgIterations);
}

template <typename Archive, typename O>
void outputFields(Archive& a, O& o, Eigen::Index ne) {
  a.field("outputs.elementForce", o.elementForce, ne, 1);
  a.field("outputs.elementLength", o.elementLength, ne, 1);
  a.field("outputs.gutVolume", o.gutVolume);
  a.field("outputs.gutPressure", o.gutPressure);
  a.field("outputs.pleuralPressure", o.pleuralPressure);
  a.field("outputs.volumeBodyVolume", o.volumeBodyVolume, o.volumeBodyVolume.size(), 1);
  a.field("outputs.volumeBodyPressure", o.volumeBodyPressure, o.volumeBodyVolume.size(), 1);
  a.field("outputs.maxJointError", o.maxJointError);
}

// the parts of Metrics that are not a double or an Eigen matrix, as matrices
struct MetricsParts {
  Eigen::VectorXi isSlack;
  Eigen::VectorXd groupMeanTension;
  Eigen::Matrix2Xd activations;  // r, alpha per group
};

template <typename Archive, typename M>
void metricsFields(Archive& a, M& m, MetricsParts& parts) {
  a.field("metrics.time", m.time);
  a.field("metrics.lungVolume", m.lungVolume);
  a.field("metrics.gutVolume", m.gutVolume);
  a.field("metrics.gutVolumeError", m.gutVolumeError);
  a.field("metrics.gutPressure", m.gutPressure);
  a.field("metrics.abdomenVolume", m.abdomenVolume);
  a.field("metrics.volumeBodyError", m.volumeBodyError);
  a.field("metrics.elementForce", m.elementForce);
  a.field("metrics.isSlack", parts.isSlack);
  a.field("metrics.groupMeanTension", parts.groupMeanTension, kElementGroupCount, 1);
  a.field("metrics.activations", parts.activations, 2, kElementGroupCount);
  a.field("metrics.kineticEnergy", m.kineticEnergy);
  a.field("metrics.elasticEnergy", m.elasticEnergy);
  a.field("metrics.gravityEnergy", m.gravityEnergy);
  a.field("metrics.maxJointError", m.maxJointError);
  a.field("metrics.landmarks", m.landmarks);
}

Eigen::Matrix2Xd activationMatrix(const Activations& a) {
  Eigen::Matrix2Xd m(2, kElementGroupCount);
  for (int g = 0; g < kElementGroupCount; ++g) m.col(g) << a[at(g)].r, a[at(g)].alpha;
  return m;
}

Activations activationsOf(const Eigen::Matrix2Xd& m) {
  Activations a{};
  for (int g = 0; g < kElementGroupCount; ++g) a[at(g)] = {m(0, g), m(1, g)};
  return a;
}

}  // namespace

void writeState(CheckpointWriter& out, const State& s) {
  const Eigen::Index nb = static_cast<Eigen::Index>(s.bodyOrientation.size());
  Eigen::Matrix4Xd q(4, nb);
  for (Eigen::Index b = 0; b < nb; ++b) q.col(b) = s.bodyOrientation[static_cast<std::size_t>(b)].coeffs();
  stateFields(out, s, q, nb, s.nodePosition.cols());
}

State readState(CheckpointReader& in, const Model& model) {
  const Eigen::Index nb = model.bodies.size();
  State s;
  Eigen::Matrix4Xd q;
  stateFields(in, s, q, nb, static_cast<Eigen::Index>(model.nodes.size()));
  s.bodyOrientation.resize(static_cast<std::size_t>(nb));
  for (Eigen::Index b = 0; b < nb; ++b) s.bodyOrientation[static_cast<std::size_t>(b)].coeffs() = q.col(b);
  return s;
}

void writeSolverMemory(CheckpointWriter& out, const SolverMemory& m) {
  // the values of A0, not its factors: BlockLdlt::factorize() is a function of the values and the analysis,
  // so factoring them again gives the factorization's bits
  const int slots = m.hasFactorization ? m.system.valueBlocks() : 0;
  Eigen::Matrix<double, 9, Eigen::Dynamic> values(9, slots);
  for (int k = 0; k < slots; ++k)
    values.col(k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(m.system.value(k).data());
  solverFields(out, m, values);
}

void readSolverMemory(CheckpointReader& in, SolverMemory& m) {
  Eigen::Matrix<double, 9, Eigen::Dynamic> values;
  solverFields(in, m, values);
  m.system.clearValues();
  if (m.hasFactorization) {
    for (int k = 0; k < m.system.valueBlocks(); ++k)
      Eigen::Map<Eigen::Matrix<double, 9, 1>>(m.system.value(k).data()) = values.col(k);
    if (!m.system.factorize()) in.fail("solver.systemValues", "the stored matrix is not positive definite");
  }
  const Eigen::Index nf = 3 * static_cast<Eigen::Index>(m.system.blocks());
  const bool fits = m.rankOne.size() == nf && m.rankOneSolve.size() == nf &&
                    (m.rankTwo.size() == 0 || (m.rankTwo.size() == nf && m.rankTwoSolve.size() == nf)) &&
                    m.volumeRank.rows() == nf && m.volumeRankSolve.rows() == nf &&
                    m.volumeRankSolve.cols() == m.volumeRank.cols() &&
                    m.volumeRankScale.size() == m.volumeRank.cols();
  if (m.hasFactorization && !fits)
    in.fail("solver.rankOne", "sizes do not match the model's free coordinates");
}

void writeStepOutputs(CheckpointWriter& out, const StepOutputs& o) {
  outputFields(out, o, o.elementForce.size());
}

void readStepOutputs(CheckpointReader& in, StepOutputs& o) { outputFields(in, o, o.elementForce.size()); }

void writeActivations(CheckpointWriter& out, const std::string& key, const Activations& a) {
  out.write(key, activationMatrix(a));
}

Activations readActivations(CheckpointReader& in, const std::string& key) {
  Eigen::Matrix2Xd m;
  in.readSized(key, m, 2, kElementGroupCount);
  return activationsOf(m);
}

void writeMetrics(CheckpointWriter& out, const Metrics& m) {
  MetricsParts parts;
  parts.isSlack.resize(static_cast<Eigen::Index>(m.isSlack.size()));
  for (std::size_t e = 0; e < m.isSlack.size(); ++e)
    parts.isSlack(static_cast<Eigen::Index>(e)) = m.isSlack[e];
  parts.groupMeanTension = Eigen::Map<const Eigen::VectorXd>(m.groupMeanTension.data(), kElementGroupCount);
  parts.activations = activationMatrix(m.activations);
  metricsFields(out, m, parts);
}

void readMetrics(CheckpointReader& in, Metrics& m) {
  MetricsParts parts;
  metricsFields(in, m, parts);
  m.isSlack.assign(static_cast<std::size_t>(parts.isSlack.size()), 0);
  for (Eigen::Index e = 0; e < parts.isSlack.size(); ++e)
    m.isSlack[static_cast<std::size_t>(e)] = static_cast<std::uint8_t>(parts.isSlack(e));
  for (int g = 0; g < kElementGroupCount; ++g) m.groupMeanTension[at(g)] = parts.groupMeanTension(g);
  m.activations = activationsOf(parts.activations);
}

}  // namespace pneuma::sim
