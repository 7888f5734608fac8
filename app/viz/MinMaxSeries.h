#pragma once
/// @file MinMaxSeries.h
/// A time series thinned for plotting in bounded memory: consecutive samples are gathered in buckets, and
/// each bucket keeps only its smallest and its largest sample (with their times), so the plotted curve keeps
/// every peak and trough however long the run. When the buckets run out, neighbours merge pairwise (each
/// bucket then spans twice as many samples). Up to `maxBuckets` samples the series is exact.

#include <cstddef>
#include <vector>

namespace pneuma::viz {

class MinMaxSeries {
 public:
  /// @param maxBuckets  most buckets kept (even, >= 2); the series yields at most 2 * maxBuckets points
  explicit MinMaxSeries(std::size_t maxBuckets = 1024);

  /// Appends sample (t, v); t must not decrease.
  void append(double t, double v);
  /// Number of samples appended so far.
  std::size_t sampleCount() const { return m_samples; }
  /// The thinned curve in time order: one point per single-sample bucket, else its minimum and its maximum.
  void points(std::vector<double>& t, std::vector<double>& v) const;

  /// One bucket: its smallest and its largest sample, with their times.
  struct Bucket {
    double tMin, vMin, tMax, vMax;
  };
  /// The buckets in time order. Which samples share a bucket depends only on how many were appended, so
  /// series fed the same samples (the columns of one table) have buckets that span the same samples.
  const std::vector<Bucket>& buckets() const { return m_buckets; }

 private:
  void mergePairs();
  std::size_t m_maxBuckets;
  std::size_t m_span = 1;    // samples per bucket
  std::size_t m_inLast = 0;  // samples in the last bucket
  std::size_t m_samples = 0;
  std::vector<Bucket> m_buckets;
};

}  // namespace pneuma::viz
