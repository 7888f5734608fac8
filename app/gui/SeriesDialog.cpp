#include "gui/SeriesDialog.h"

#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QSpinBox>

namespace pneuma::app {

namespace {

// "1st", "2nd", "3rd", "4th", ..., "11th", "12th", "13th", "21st"
QString ordinal(int n) {
  const int tens = n % 100, ones = n % 10;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : ones == 1                ? "st"
                       : ones == 2                ? "nd"
                       : ones == 3                ? "rd"
                                                  : "th";
  return QString::number(n) + suffix;
}

}  // namespace

SeriesDialog::SeriesDialog(double recordedFrom, double recordedTo, std::size_t recordedFrames,
                           double frameBytes, QWidget* parent)
    : RangeDialog("Export run as ParaView series", "run.pvd", "ParaView data (*.pvd)", recordedFrom,
                  recordedTo, parent),
      m_recordedFrom(recordedFrom),
      m_recordedTo(recordedTo),
      m_recordedFrames(recordedFrames),
      m_frameBytes(frameBytes) {
  m_stride = new QSpinBox(this);
  m_stride->setRange(1, 1000);
  m_stride->setPrefix("every ");
  m_stride->setSuffix(" recorded frame(s)");
  form()->addRow("Stride", m_stride);
  connect(m_stride, qOverload<int>(&QSpinBox::valueChanged), this, [this] { update(); });
  finishLayout();
}

viz::SeriesRange SeriesDialog::range() const {
  viz::SeriesRange r;
  r.from = fromBox()->value();
  r.to = toBox()->value();
  r.stride = m_stride->value();
  return r;
}

int SeriesDialog::frameCount() const { return range().count(m_recordedFrames, m_recordedFrom, m_recordedTo); }

void SeriesDialog::update() {
  const viz::SeriesRange r = range();
  const int frames = frameCount();
  if (QFileInfo(path()).suffix().toLower() != "pvd")
    return showSummary("Choose a .pvd file: the frames go to a folder of the same name beside it.", false);
  if (r.to < r.from) return showSummary("Nothing to export: From must come before To.", false);
  if (frames == 0) return showSummary("No recorded frame lies in that range.", false);
  const double recordedRate =
      m_recordedFrames > 1 && m_recordedTo > m_recordedFrom
          ? static_cast<double>(m_recordedFrames - 1) / (m_recordedTo - m_recordedFrom)
          : 0.0;  // [1/s]
  showSummary(
      QString("%1 frames (every %2 recorded frame: %3 per second, %4 s to %5 s), 7 files each, about %6")
          .arg(frames)
          .arg(ordinal(r.stride))
          .arg(recordedRate / r.stride, 0, 'g', 3)
          .arg(r.from, 0, 'f', 2)
          .arg(r.to, 0, 'f', 2)
          .arg(byteText(m_frameBytes * frames)),
      true);
}

}  // namespace pneuma::app
