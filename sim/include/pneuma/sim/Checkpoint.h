#pragma once
/// @file Checkpoint.h
/// Exact restarts from a file: a small text format for what a run continues from (the State, the implicit
/// solver's memory, the last step's outputs, the latest Metrics and the controller's state;
/// Simulation::save()). One field per line, `key value...`; arrays as `key rows cols v00 v10 ...`
/// (column-major). Doubles are written as hexadecimal floating point (C99 %a), so a value read back has the
/// bits it was written with; integers in decimal; strings as `key length bytes`. The reader checks every key
/// in order and names the first one that does not match, so a file from another model or version fails with a
/// message instead of resuming wrongly.

#include <Eigen/Core>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <utility>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {

/// Writes checkpoint fields to a stream (see the file comment).
class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::ostream& out) : m_out(out) {}

  void write(const std::string& key, double value);
  void write(const std::string& key, long long value);
  void write(const std::string& key, int value) { write(key, static_cast<long long>(value)); }
  void write(const std::string& key, std::uint64_t value);
  void write(const std::string& key, bool value) { write(key, static_cast<long long>(value ? 1 : 0)); }
  void write(const std::string& key, const std::string& value);
  void write(const std::string& key, const char* value) { write(key, std::string(value)); }
  /// The writer's side of a field list walked by both (Checkpoint.cpp): write(); the shape is the reader's
  /// check.
  template <typename T>
  void field(const std::string& key, const T& value) {
    write(key, value);
  }
  template <typename T>
  void field(const std::string& key, const T& value, Eigen::Index rows, Eigen::Index cols) {
    (void)rows;
    (void)cols;
    write(key, value);
  }
  /// A dense double or int matrix: rows, cols, then the entries column by column.
  template <typename Derived>
  void write(const std::string& key, const Eigen::DenseBase<Derived>& m) {
    beginArray(key, m.rows(), m.cols());
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i) scalar(m(i, j));
    endLine();
  }

 private:
  void beginArray(const std::string& key, Eigen::Index rows, Eigen::Index cols);
  void scalar(double v);
  void scalar(int v);
  void endLine();
  std::ostream& m_out;
};

/// Reads what a CheckpointWriter wrote, field by field in the same order.
/// Every read throws Error naming `source`, the expected key and what was found when the key, a number or the
/// shape of a fixed-size matrix does not match, or the stream ends.
class CheckpointReader {
 public:
  CheckpointReader(std::istream& in, std::string source) : m_in(in), m_source(std::move(source)) {}

  double readDouble(const std::string& key);
  long long readInt(const std::string& key);
  std::uint64_t readUnsigned(const std::string& key);
  bool readBool(const std::string& key) { return readInt(key) != 0; }
  std::string readString(const std::string& key);
  /// A dense double or int matrix, resized to the stored shape (which must fit a fixed-size type).
  template <typename Derived>
  void read(const std::string& key, Eigen::PlainObjectBase<Derived>& m) {
    const auto [rows, cols] = beginArray(key);
    constexpr int kRows = Derived::RowsAtCompileTime, kCols = Derived::ColsAtCompileTime;
    if ((kRows != Eigen::Dynamic && rows != kRows) || (kCols != Eigen::Dynamic && cols != kCols))
      fail(key, "shape " + std::to_string(rows) + " x " + std::to_string(cols) + " does not fit");
    m.resize(rows, cols);
    for (Eigen::Index j = 0; j < cols; ++j)
      for (Eigen::Index i = 0; i < rows; ++i) scalar(key, m.coeffRef(i, j));
  }
  /// Like read(), and throws unless the stored shape is rows x cols.
  template <typename Derived>
  void readSized(const std::string& key, Eigen::PlainObjectBase<Derived>& m, Eigen::Index rows,
                 Eigen::Index cols) {
    read(key, m);
    if (m.rows() != rows || m.cols() != cols)
      fail(key, "shape " + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) + ", expected " +
                    std::to_string(rows) + " x " + std::to_string(cols));
  }
  /// The reader's side of a field list walked by both (Checkpoint.cpp).
  void field(const std::string& key, double& v) { v = readDouble(key); }
  void field(const std::string& key, long long& v) { v = readInt(key); }
  void field(const std::string& key, int& v);
  void field(const std::string& key, bool& v) { v = readBool(key); }
  template <typename Derived>
  void field(const std::string& key, Eigen::PlainObjectBase<Derived>& m) {
    read(key, m);
  }
  template <typename Derived>
  void field(const std::string& key, Eigen::PlainObjectBase<Derived>& m, Eigen::Index rows,
             Eigen::Index cols) {
    readSized(key, m, rows, cols);
  }
  /// @throws Error naming the source and `key`.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  void expectKey(const std::string& key);
  std::string token(const std::string& key);
  std::pair<Eigen::Index, Eigen::Index> beginArray(const std::string& key);
  void scalar(const std::string& key, double& v);
  void scalar(const std::string& key, int& v);
  std::istream& m_in;
  std::string m_source;
};

/// The State, exactly.
void writeState(CheckpointWriter& out, const State& state);
/// Reads a State written by writeState() for `model`. @throws Error when its sizes are not the model's.
State readState(CheckpointReader& in, const Model& model);

/// The implicit solver's memory: the factored matrix's values (not its factors: readSolverMemory() factors
/// them again, which gives the same bits), the Sherman-Morrison vectors, the factorization's snapshot and
/// age, and the last CG iteration count.
void writeSolverMemory(CheckpointWriter& out, const SolverMemory& memory);
/// Reads into `memory`, which must come from makeStepWork() of the same model (it holds the symbolic
/// analysis).
/// @throws Error when the sizes do not match or the stored matrix cannot be factored.
void readSolverMemory(CheckpointReader& in, SolverMemory& memory);

/// The last step's outputs.
void writeStepOutputs(CheckpointWriter& out, const StepOutputs& outputs);
void readStepOutputs(CheckpointReader& in, StepOutputs& outputs);

/// One frame's Metrics, every field.
void writeMetrics(CheckpointWriter& out, const Metrics& metrics);
void readMetrics(CheckpointReader& in, Metrics& metrics);

/// Activations (r and alpha per group).
void writeActivations(CheckpointWriter& out, const std::string& key, const Activations& a);
Activations readActivations(CheckpointReader& in, const std::string& key);

}  // namespace pneuma::sim
