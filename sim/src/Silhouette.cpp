#include "pneuma/sim/Silhouette.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace pneuma::sim {

namespace {

using Span = std::pair<double, double>;

int axisOf(SilhouetteView view) { return view == SilhouetteView::Lateral ? 1 : 0; }

// the union of intervals, sorted and disjoint
std::vector<Span> merged(std::vector<Span> in) {
  std::sort(in.begin(), in.end());
  std::vector<Span> out;
  for (const Span& s : in) {
    if (!out.empty() && s.first <= out.back().second)
      out.back().second = std::max(out.back().second, s.second);
    else
      out.push_back(s);
  }
  return out;
}

// the segment in which triangle f cuts the plane z, as its two ends (u, w) (u the view's horizontal axis, w
// the other), or false when it does not cut it: a vertex counts as above when z_v >= z (a consistent
// tie-break, so that a closed mesh's slice is closed); each crossing is interpolated from the edge's
// lower-index vertex, so the two triangles of an edge give the same point
bool cut(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& t, Eigen::Index f, int axis, double z,
         Eigen::Vector2d& p, Eigen::Vector2d& q) {
  const int other = 1 - axis;
  int found = 0;
  for (int e = 0; e < 3; ++e) {
    int a = t(e, f), b = t((e + 1) % 3, f);
    if (a > b) std::swap(a, b);
    const double sa = x(2, a) - z, sb = x(2, b) - z;
    if ((sa >= 0.0) == (sb >= 0.0)) continue;
    const double r = sa / (sa - sb);
    const Eigen::Vector2d c(x(axis, a) + (x(axis, b) - x(axis, a)) * r,
                            x(other, a) + (x(other, b) - x(other, a)) * r);
    (found == 0 ? p : q) = c;
    ++found;
  }
  return found == 2;
}

// the spans of one slice: the u extents of its segments within the band |w| <= band, and the slice's chords
// along the band's edges w = +-band (pairs of the sorted crossings of the edge, inside between odd and even)
class SliceSpans {
 public:
  explicit SliceSpans(double band) : m_band(band) {}
  void add(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    if (!std::isfinite(m_band)) {
      m_pieces.emplace_back(std::min(p.x(), q.x()), std::max(p.x(), q.x()));
      return;
    }
    // clip the segment to the band
    double t0 = 0.0, t1 = 1.0;
    const double dw = q.y() - p.y();
    for (const double edge : {-m_band, m_band}) {
      if ((p.y() >= edge) != (q.y() >= edge))
        m_crossings[edge > 0].push_back(p.x() + (q.x() - p.x()) * (edge - p.y()) / dw);
      if (dw == 0.0) continue;
      const double te = (edge - p.y()) / dw;
      if ((edge > 0) == (dw > 0))
        t1 = std::min(t1, te);
      else
        t0 = std::max(t0, te);
    }
    if (dw == 0.0 && std::abs(p.y()) > m_band) return;
    if (t0 > t1) return;
    const double u0 = p.x() + (q.x() - p.x()) * t0, u1 = p.x() + (q.x() - p.x()) * t1;
    m_pieces.emplace_back(std::min(u0, u1), std::max(u0, u1));
  }
  std::vector<Span> take() {
    for (std::vector<double>& c : m_crossings) {
      std::sort(c.begin(), c.end());
      for (std::size_t i = 0; i + 1 < c.size(); i += 2) m_pieces.emplace_back(c[i], c[i + 1]);
    }
    return merged(std::move(m_pieces));
  }

 private:
  double m_band;
  std::vector<Span> m_pieces;
  std::array<std::vector<double>, 2> m_crossings;  // u where the slice crosses w = -band, w = +band
};

}  // namespace

const char* silhouetteViewName(SilhouetteView view) {
  return view == SilhouetteView::Lateral ? "lateral" : "frontal";
}

Eigen::Vector4d SilhouetteOutline::bounds() const {
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  bool isFirst = true;
  for (const Eigen::Matrix2Xd& loop : loops) {
    if (loop.cols() == 0) continue;
    const Eigen::Vector2d lo = loop.rowwise().minCoeff(), hi = loop.rowwise().maxCoeff();
    if (isFirst) b << lo, hi;
    b.head<2>() = b.head<2>().cwiseMin(lo);
    b.tail<2>() = b.tail<2>().cwiseMax(hi);
    isFirst = false;
  }
  return b;
}

std::vector<std::pair<double, double>> silhouetteSpans(const Eigen::Matrix3Xd& vertices,
                                                       const Eigen::Matrix3Xi& triangles, SilhouetteView view,
                                                       double z, double band) {
  const int axis = axisOf(view);
  SliceSpans spans(band);
  Eigen::Vector2d p, q;
  for (Eigen::Index f = 0; f < triangles.cols(); ++f)
    if (cut(vertices, triangles, f, axis, z, p, q)) spans.add(p, q);
  return spans.take();
}

double silhouetteWidth(const Eigen::Matrix3Xd& vertices, const Eigen::Matrix3Xi& triangles,
                       SilhouetteView view, double z, double band) {
  const std::vector<Span> spans = silhouetteSpans(vertices, triangles, view, z, band);
  return spans.empty() ? 0.0 : spans.back().second - spans.front().first;
}

SilhouetteOutline silhouetteOutline(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& t, SilhouetteView view,
                                    double spacing, double band) {
  SilhouetteOutline out;
  out.view = view;
  if (x.cols() == 0 || t.cols() == 0 || !(spacing > 0.0)) return out;
  const int axis = axisOf(view);

  // the grid: two empty rows and columns of padding on every side, so every outline point has two cells
  const double uMin = x.row(axis).minCoeff(), uMax = x.row(axis).maxCoeff();
  const double zMin = x.row(2).minCoeff(), zMax = x.row(2).maxCoeff();
  constexpr double kMaxCells = 4e6;
  double h = spacing;
  const double cells = (uMax - uMin) * (zMax - zMin) / (h * h);
  if (cells > kMaxCells) h *= std::sqrt(cells / kMaxCells);
  out.spacing = h;
  const double u0 = uMin - 2.0 * h, z0 = zMin - 2.0 * h;
  const int nu = static_cast<int>(std::ceil((uMax - u0) / h)) + 3;  // columns
  const int nz = static_cast<int>(std::ceil((zMax - z0) / h)) + 3;  // rows
  const auto col = [&](int k) { return u0 + k * h; };
  const auto row = [&](int j) { return z0 + j * h; };

  // the rows' spans: each triangle adds its cut segment to the rows it spans
  std::vector<SliceSpans> rows(static_cast<std::size_t>(nz), SliceSpans(band));
  Eigen::Vector2d p, q;
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const double lo = std::min({x(2, t(0, f)), x(2, t(1, f)), x(2, t(2, f))});
    const double hi = std::max({x(2, t(0, f)), x(2, t(1, f)), x(2, t(2, f))});
    const int j0 = std::max(0, static_cast<int>(std::floor((lo - z0) / h)));
    const int j1 = std::min(nz - 1, static_cast<int>(std::ceil((hi - z0) / h)));
    for (int j = j0; j <= j1; ++j)
      if (cut(x, t, f, axis, row(j), p, q)) rows[static_cast<std::size_t>(j)].add(p, q);
  }
  // each row's span ends, sorted: start, end, start, end, ...
  std::vector<std::vector<double>> ends(static_cast<std::size_t>(nz));
  for (int j = 0; j < nz; ++j)
    for (const Span& m : rows[static_cast<std::size_t>(j)].take()) {
      ends[static_cast<std::size_t>(j)].push_back(m.first);
      ends[static_cast<std::size_t>(j)].push_back(m.second);
    }

  // the field: signed distance along the row to the nearest span end, inside >= 0, clamped to [-h, h]
  Eigen::MatrixXd field(nu, nz);
  for (int j = 0; j < nz; ++j) {
    const std::vector<double>& e = ends[static_cast<std::size_t>(j)];
    for (int k = 0; k < nu; ++k) {
      const double u = col(k);
      const auto i = static_cast<std::size_t>(std::upper_bound(e.begin(), e.end(), u) - e.begin());
      double d = h;
      if (i > 0) d = std::min(d, u - e[i - 1]);
      if (i < e.size()) d = std::min(d, e[i] - u);
      field(k, j) = i % 2 == 1 ? d : -std::max(d, 1e-12 * h);
    }
  }
  const auto inside = [&](int k, int j) { return field(k, j) >= 0.0; };

  // an outline point per cell edge that changes sign: horizontal edges (along a row) exactly at the span end
  // inside them, vertical edges (between rows) by linear interpolation
  const auto hId = [&](int k, int j) { return 2LL * (static_cast<long long>(j) * nu + k); };
  const auto vId = [&](int k, int j) { return 2LL * (static_cast<long long>(j) * nu + k) + 1; };
  std::unordered_map<long long, Eigen::Vector2d> point;
  const auto hPoint = [&](int k, int j) {
    const long long id = hId(k, j);
    if (!point.count(id)) {
      const std::vector<double>& e = ends[static_cast<std::size_t>(j)];
      auto it = std::upper_bound(e.begin(), e.end(), col(k));
      const double u = it != e.end() && *it <= col(k + 1) ? *it : 0.5 * (col(k) + col(k + 1));
      point[id] = Eigen::Vector2d(u, row(j));
    }
    return id;
  };
  const auto vPoint = [&](int k, int j) {
    const long long id = vId(k, j);
    if (!point.count(id)) {
      const double a = field(k, j), b = field(k, j + 1);
      point[id] = Eigen::Vector2d(col(k), row(j) + h * a / (a - b));
    }
    return id;
  };

  // marching squares: corners 0 (k, j), 1 (k+1, j), 2 (k+1, j+1), 3 (k, j+1); edges bottom, right, top, left;
  // a segment joins two crossing edges; in a saddle the segments cut off the corners that differ from the
  // cell centre (the mean of the corners)
  std::unordered_map<long long, std::array<long long, 2>> next;
  const auto link = [&](long long a, long long b) {
    for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, a}}) {
      std::array<long long, 2>& n = next.try_emplace(p, std::array<long long, 2>{-1, -1}).first->second;
      n[n[0] < 0 ? 0 : 1] = q;
    }
  };
  for (int j = 0; j + 1 < nz; ++j)
    for (int k = 0; k + 1 < nu; ++k) {
      const std::array<bool, 4> in{inside(k, j), inside(k + 1, j), inside(k + 1, j + 1), inside(k, j + 1)};
      const int count = in[0] + in[1] + in[2] + in[3];
      if (count == 0 || count == 4) continue;
      const auto edge = [&](int e) {
        switch (e) {
          case 0:
            return hPoint(k, j);
          case 1:
            return vPoint(k + 1, j);
          case 2:
            return hPoint(k, j + 1);
          default:
            return vPoint(k, j);
        }
      };
      if (count == 2 && in[0] == in[2]) {
        const double centre = field(k, j) + field(k + 1, j) + field(k + 1, j + 1) + field(k, j + 1);
        const bool isCentreInside = centre >= 0.0;
        // corner c lies between edges c - 1 and c (cyclically)
        for (int c = 0; c < 4; ++c)
          if (in[static_cast<std::size_t>(c)] != isCentreInside) link(edge((c + 3) % 4), edge(c));
        continue;
      }
      long long ends2[2];
      int n = 0;
      for (int e = 0; e < 4; ++e)
        if (in[static_cast<std::size_t>(e)] != in[static_cast<std::size_t>((e + 1) % 4)])
          ends2[n++] = edge(e);
      link(ends2[0], ends2[1]);
    }

  // walk the links into closed loops
  std::unordered_map<long long, bool> isVisited;
  for (const auto& [start, unused] : next) {
    if (isVisited[start]) continue;
    std::vector<Eigen::Vector2d> loop;
    long long prev = -1, cur = start;
    while (cur >= 0 && !isVisited[cur]) {
      isVisited[cur] = true;
      loop.push_back(point.at(cur));
      const std::array<long long, 2>& n = next.at(cur);
      const long long step = n[0] != prev ? n[0] : n[1];
      prev = cur;
      cur = step;
    }
    Eigen::Matrix2Xd m(2, static_cast<Eigen::Index>(loop.size()));
    for (std::size_t i = 0; i < loop.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = loop[i];
    out.loops.push_back(std::move(m));
  }
  // a deterministic order: by the loops' lowest point
  std::sort(out.loops.begin(), out.loops.end(), [](const Eigen::Matrix2Xd& a, const Eigen::Matrix2Xd& b) {
    const auto key = [](const Eigen::Matrix2Xd& m) {
      return std::pair{m.row(1).minCoeff(), m.row(0).minCoeff()};
    };
    return key(a) < key(b);
  });
  return out;
}

}  // namespace pneuma::sim
