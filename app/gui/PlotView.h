#pragma once
/// @file PlotView.h
/// A live line chart drawn with QPainter (cheap enough for 60 Hz): series over a rolling time window,
/// horizontal reference lines (tolerance bands), a time cursor with its read-out, and a note line
/// (e.g. the current tidal volume). It paints the geometry viz::layoutPlot() computes for its content as a
/// viz::Plot, the same content and function the PNG/SVG/PDF export uses (at a larger scale), so an export
/// has the screen's ranges, ticks and legend; the CSV export holds exactly the plotted data.

#include <QColor>
#include <QString>
#include <QWidget>
#include <vector>

#include "viz/Plot.h"
#include "viz/PlotLayout.h"

namespace pneuma::app {

class PlotView : public QWidget {
  Q_OBJECT

 public:
  struct Series {
    QString name;
    QColor colour;
    bool isDashed = false;
    std::vector<double> y;  ///< one value per time sample, in the y axis unit; NaN leaves a gap
    QString legend;         ///< legend text; empty: no legend entry (the CSV header still uses `name`)
  };
  struct Reference {
    QString name;
    double y = 0.0;  ///< in the y axis unit
    QColor colour;
  };

  /// @param title   headline
  /// @param yLabel  y axis label with unit, e.g. "lung-cavity volume [mL]"
  PlotView(QString title, QString yLabel, QWidget* parent = nullptr);

  /// Replaces the data: shared time samples [s] and one Series per curve (each of time.size() values).
  void setData(std::vector<double> time, std::vector<Series> series);
  void setReferences(std::vector<Reference> references);
  /// Time span shown [s], ending at the newest sample or at viewEnd() (0 = everything).
  void setWindow(double seconds);
  double window() const { return m_window; }
  /// Right edge of the shown span [s]; NaN follows the newest sample (the default). The wheel zooms the span
  /// (about the time under the mouse), a drag scrolls it, a double click follows the newest sample again.
  void setViewEnd(double time);
  double viewEnd() const { return m_end; }
  /// Vertical cursor at time [s] (NaN hides it); the read-out lists each series' value there in the y unit.
  /// A cursor outside the shown span scrolls the span to centre it (the plots follow the timeline).
  void setCursor(double time);
  /// One line of text under the title, e.g. "tidal volume 498 mL".
  void setNote(QString note);
  /// Always include 0 in the y range (e.g. tensions).
  void setIncludeZero(bool includeZero);

  QString title() const { return m_title; }
  QString yLabel() const { return m_yLabel; }
  const std::vector<double>& time() const { return m_time; }
  const std::vector<Series>& series() const { return m_series; }
  /// Value of series `i` at the cursor (nearest sample), NaN when there is none.
  double cursorValue(std::size_t i) const;

  /// The same chart as a viz::Plot (shown window only), for PNG and SVG export: this widget at twice its size
  /// (or more, to be at least 960 px wide), text and lines scaled alike, so it lays out with the same ticks.
  viz::Plot toPlot() const;
  /// The chart as a viz::Plot at `scale` times this widget's size and line height.
  viz::Plot toPlot(double scale) const;
  /// The geometry painted on screen (viz::layoutPlot() with this widget's size and font).
  viz::PlotLayout layout() const;
  /// The shown data as CSV: "time [s],<series name> [<unit>],..." then one row per sample.
  std::string toCsv() const;

 signals:
  /// The user asked for the context menu (export actions).
  void contextMenuRequested(const QPoint& globalPos);
  /// The user zoomed or scrolled: the new span [s] and right edge [s] (NaN: following the newest sample).
  void viewChanged(double window, double end);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void contextMenuEvent(QContextMenuEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;

 private:
  std::size_t firstShown() const;
  std::size_t endShown() const;  // one past the last sample shown
  double shownEnd() const;       // [s] right edge of the span
  viz::PlotLayout layoutOf(const viz::Plot& plot) const;
  QString unit() const;

  QString m_title;
  QString m_yLabel;
  QString m_note;
  std::vector<double> m_time;
  std::vector<Series> m_series;
  std::vector<Reference> m_references;
  double m_window = 20.0;   // [s]
  double m_cursor;          // [s], NaN = none
  double m_end;             // [s] right edge, NaN = the newest sample
  double m_dragFrom = 0.0;  // [px] x of the last drag position
  bool m_includeZero = false;
};

}  // namespace pneuma::app
