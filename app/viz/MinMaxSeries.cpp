#include "viz/MinMaxSeries.h"

#include <algorithm>
#include <stdexcept>

namespace pneuma::viz {

MinMaxSeries::MinMaxSeries(std::size_t maxBuckets) : m_maxBuckets(maxBuckets) {
  if (maxBuckets < 2 || maxBuckets % 2 != 0)
    throw std::invalid_argument("MinMaxSeries: maxBuckets must be even, >= 2");
  m_buckets.reserve(maxBuckets);
}

void MinMaxSeries::append(double t, double v) {
  ++m_samples;
  if (!m_buckets.empty() && m_inLast < m_span) {
    Bucket& b = m_buckets.back();
    // NaN never becomes an extreme (comparisons with it are false)
    if (v < b.vMin || b.vMin != b.vMin) b.vMin = v, b.tMin = t;
    if (v > b.vMax || b.vMax != b.vMax) b.vMax = v, b.tMax = t;
    ++m_inLast;
    return;
  }
  if (m_buckets.size() == m_maxBuckets) mergePairs();
  m_buckets.push_back({t, v, t, v});
  m_inLast = 1;
}

void MinMaxSeries::mergePairs() {
  std::size_t j = 0;
  for (std::size_t i = 0; i + 1 < m_buckets.size(); i += 2, ++j) {
    const Bucket& a = m_buckets[i];
    const Bucket& b = m_buckets[i + 1];
    Bucket m = a;
    if (b.vMin < m.vMin || m.vMin != m.vMin) m.vMin = b.vMin, m.tMin = b.tMin;
    if (b.vMax > m.vMax || m.vMax != m.vMax) m.vMax = b.vMax, m.tMax = b.tMax;
    m_buckets[j] = m;
  }
  m_buckets.resize(j);  // m_maxBuckets is even: every bucket had a partner, and all were full
  m_span *= 2;
  m_inLast = m_span;  // the last merged bucket is full
}

void MinMaxSeries::points(std::vector<double>& t, std::vector<double>& v) const {
  t.clear();
  v.clear();
  t.reserve(2 * m_buckets.size());
  v.reserve(2 * m_buckets.size());
  for (const Bucket& b : m_buckets) {
    const bool minFirst = b.tMin <= b.tMax;
    t.push_back(minFirst ? b.tMin : b.tMax);
    v.push_back(minFirst ? b.vMin : b.vMax);
    if (b.tMin == b.tMax) continue;
    t.push_back(minFirst ? b.tMax : b.tMin);
    v.push_back(minFirst ? b.vMax : b.vMin);
  }
}

}  // namespace pneuma::viz
