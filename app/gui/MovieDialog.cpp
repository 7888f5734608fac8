#include "gui/MovieDialog.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QVBoxLayout>

#include "viz/MovieWriter.h"

namespace pneuma::app {

namespace {

const char* formatName(viz::MovieWriter::Format format) {
  switch (format) {
    case viz::MovieWriter::Format::Mp4:
      return "MP4 (H.264)";
    case viz::MovieWriter::Format::Ogg:
      return "Ogg Theora";
    case viz::MovieWriter::Format::PngSequence:
      break;
  }
  return "PNG sequence";
}

}  // namespace

const std::vector<QSize>& MovieDialog::sizes() {
  static const std::vector<QSize> offered = {{640, 360}, {1280, 720}, {1920, 1080}};
  return offered;
}

MovieDialog::MovieDialog(double recordedFrom, double recordedTo, QSize shownSize, QWidget* parent)
    : RangeDialog(
          "Export animation",
          viz::MovieWriter::ffmpegProgram().empty() ? "breathing.ogv" : "breathing.mp4",  // MP4 if it can
          "MP4 movie, H.264 (*.mp4);;Ogg Theora movie (*.ogv);;PNG sequence (*.png)", recordedFrom,
          recordedTo, parent),
      m_shownSize(shownSize) {
  m_size = new QComboBox(this);
  m_size->addItem(QString("as shown (%1 x %2)").arg(shownSize.width()).arg(shownSize.height()));
  for (const QSize& s : sizes()) m_size->addItem(QString("%1 x %2").arg(s.width()).arg(s.height()));
  form()->addRow("Size", m_size);

  m_timeStamp = new QCheckBox("Time stamp", this);
  m_volumePanel = new QCheckBox("Volume panel with a cursor", this);
  auto* overlays = new QVBoxLayout;
  overlays->addWidget(m_timeStamp);
  overlays->addWidget(m_volumePanel);
  form()->addRow("Overlays", overlays);

  connect(m_size, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] { update(); });
  finishLayout();
}

ExportController::MovieOptions MovieDialog::options() const {
  ExportController::MovieOptions o;
  o.from = fromBox()->value();
  o.to = toBox()->value();
  if (m_size->currentIndex() > 0) o.size = sizes()[static_cast<std::size_t>(m_size->currentIndex() - 1)];
  o.hasTimeStamp = m_timeStamp->isChecked();
  o.hasVolumePanel = m_volumePanel->isChecked();
  return o;
}

void MovieDialog::update() {
  const ExportController::MovieOptions o = options();
  const int frames = ExportController::frameCount(o);
  const auto format = viz::MovieWriter::formatOf(path().toStdString());
  if (path().trimmed().isEmpty())
    return showSummary("Choose a file: .mp4, .ogv, or .png for a PNG sequence.", false);
  if (frames == 0) return showSummary("Nothing to export: From must come before To.", false);
  if (format == viz::MovieWriter::Format::Mp4 && viz::MovieWriter::ffmpegProgram().empty())
    return showSummary(QString::fromStdString(viz::MovieWriter::ffmpegMissingMessage()) + ".", false);
  QSize size = o.size.isValid() ? o.size : m_shownSize;
  if (format != viz::MovieWriter::Format::PngSequence) size = QSize(size.width() & ~1, size.height() & ~1);
  showSummary(
      QString("%1 frames (%2 s at %3 fps), %4 x %5 px, %6, about %7")
          .arg(frames)
          .arg(o.to - o.from, 0, 'f', 2)
          .arg(o.fps, 0, 'g', 3)
          .arg(size.width())
          .arg(size.height())
          .arg(formatName(format))
          .arg(byteText(viz::MovieWriter::estimatedBytes(format, size.width(), size.height(), frames))),
      true);
}

}  // namespace pneuma::app
