#include "gui/MovieDialog.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>
#include <algorithm>

#include "viz/MovieWriter.h"

namespace pneuma::app {

namespace {

// "2.8 MB", "640 kB", "1.3 GB"
QString byteText(double bytes) {
  if (bytes >= 1e9) return QString("%1 GB").arg(bytes / 1e9, 0, 'f', 1);
  if (bytes >= 1e6) return QString("%1 MB").arg(bytes / 1e6, 0, 'f', bytes >= 1e8 ? 0 : 1);
  return QString("%1 kB").arg(std::max(1.0, bytes / 1e3), 0, 'f', 0);
}

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
    : QDialog(parent), m_shownSize(shownSize) {
  setWindowTitle("Export animation");
  auto* form = new QFormLayout;

  // the file, MP4 unless ffmpeg is missing
  m_path = new QLineEdit(viz::MovieWriter::ffmpegProgram().empty() ? "breathing.ogv" : "breathing.mp4", this);
  auto* browse = new QPushButton("Browse\u2026", this);
  connect(browse, &QPushButton::clicked, this, [this] {
    const QString chosen = QFileDialog::getSaveFileName(
        this, "Export animation", m_path->text(),
        "MP4 movie, H.264 (*.mp4);;Ogg Theora movie (*.ogv);;PNG sequence (*.png)");
    if (!chosen.isEmpty()) m_path->setText(chosen);
  });
  auto* file = new QHBoxLayout;
  file->addWidget(m_path, 1);
  file->addWidget(browse);
  form->addRow("File", file);

  // the stretch of the recording, all of it by default
  const auto secondsBox = [&](double value) {
    auto* box = new QDoubleSpinBox(this);
    box->setRange(recordedFrom, recordedTo);
    box->setDecimals(2);
    box->setSingleStep(0.5);
    box->setSuffix(" s");
    box->setValue(value);
    return box;
  };
  m_from = secondsBox(recordedFrom);
  m_to = secondsBox(recordedTo);
  form->addRow("From", m_from);
  form->addRow("To", m_to);

  m_size = new QComboBox(this);
  m_size->addItem(QString("as shown (%1 x %2)").arg(shownSize.width()).arg(shownSize.height()));
  for (const QSize& s : sizes()) m_size->addItem(QString("%1 x %2").arg(s.width()).arg(s.height()));
  form->addRow("Size", m_size);

  m_timeStamp = new QCheckBox("Time stamp", this);
  m_volumePanel = new QCheckBox("Volume panel with a cursor", this);
  auto* overlays = new QVBoxLayout;
  overlays->addWidget(m_timeStamp);
  overlays->addWidget(m_volumePanel);
  form->addRow("Overlays", overlays);

  m_summary = new QLabel(this);
  m_summary->setWordWrap(true);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  m_ok = buttons->button(QDialogButtonBox::Ok);
  m_ok->setText("Export");
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);

  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form);
  layout->addWidget(m_summary);
  layout->addWidget(buttons);

  connect(m_path, &QLineEdit::textChanged, this, &MovieDialog::update);
  connect(m_from, qOverload<double>(&QDoubleSpinBox::valueChanged), this, &MovieDialog::update);
  connect(m_to, qOverload<double>(&QDoubleSpinBox::valueChanged), this, &MovieDialog::update);
  connect(m_size, qOverload<int>(&QComboBox::currentIndexChanged), this, &MovieDialog::update);
  update();
}

QString MovieDialog::path() const { return m_path->text(); }

void MovieDialog::setPath(const QString& path) { m_path->setText(path); }

ExportController::MovieOptions MovieDialog::options() const {
  ExportController::MovieOptions o;
  o.from = m_from->value();
  o.to = m_to->value();
  if (m_size->currentIndex() > 0) o.size = sizes()[static_cast<std::size_t>(m_size->currentIndex() - 1)];
  o.hasTimeStamp = m_timeStamp->isChecked();
  o.hasVolumePanel = m_volumePanel->isChecked();
  return o;
}

QString MovieDialog::summary() const { return m_summary->text(); }

void MovieDialog::update() {
  const ExportController::MovieOptions o = options();
  const int frames = ExportController::frameCount(o);
  const auto format = viz::MovieWriter::formatOf(path().toStdString());
  QString text;
  if (path().trimmed().isEmpty()) {
    text = "Choose a file: .mp4, .ogv, or .png for a PNG sequence.";
  } else if (frames == 0) {
    text = "Nothing to export: From must come before To.";
  } else if (format == viz::MovieWriter::Format::Mp4 && viz::MovieWriter::ffmpegProgram().empty()) {
    text = QString::fromStdString(viz::MovieWriter::ffmpegMissingMessage()) + ".";
  } else {
    QSize size = o.size.isValid() ? o.size : m_shownSize;
    if (format != viz::MovieWriter::Format::PngSequence) size = QSize(size.width() & ~1, size.height() & ~1);
    text = QString("%1 frames (%2 s at %3 fps), %4 x %5 px, %6, about %7")
               .arg(frames)
               .arg(o.to - o.from, 0, 'f', 2)
               .arg(o.fps, 0, 'g', 3)
               .arg(size.width())
               .arg(size.height())
               .arg(formatName(format))
               .arg(byteText(viz::MovieWriter::estimatedBytes(format, size.width(), size.height(), frames)));
    m_ok->setEnabled(true);
    m_summary->setText(text);
    return;
  }
  m_ok->setEnabled(false);
  m_summary->setText(text);
}

}  // namespace pneuma::app
