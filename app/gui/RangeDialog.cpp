#include "gui/RangeDialog.h"

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

namespace pneuma::app {

RangeDialog::RangeDialog(const QString& title, const QString& defaultPath, const QString& fileFilter,
                         double recordedFrom, double recordedTo, QWidget* parent)
    : QDialog(parent) {
  setWindowTitle(title);
  m_form = new QFormLayout;

  m_path = new QLineEdit(defaultPath, this);
  auto* browse = new QPushButton("Browse\u2026", this);
  connect(browse, &QPushButton::clicked, this, [this, title, fileFilter] {
    const QString chosen = QFileDialog::getSaveFileName(this, title, m_path->text(), fileFilter);
    if (!chosen.isEmpty()) m_path->setText(chosen);
  });
  auto* file = new QHBoxLayout;
  file->addWidget(m_path, 1);
  file->addWidget(browse);
  m_form->addRow("File", file);

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
  m_form->addRow("From", m_from);
  m_form->addRow("To", m_to);

  connect(m_path, &QLineEdit::textChanged, this, [this] { update(); });
  connect(m_from, qOverload<double>(&QDoubleSpinBox::valueChanged), this, [this] { update(); });
  connect(m_to, qOverload<double>(&QDoubleSpinBox::valueChanged), this, [this] { update(); });
}

void RangeDialog::finishLayout() {
  m_summary = new QLabel(this);
  m_summary->setWordWrap(true);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  m_ok = buttons->button(QDialogButtonBox::Ok);
  m_ok->setText("Export");
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(m_form);
  layout->addWidget(m_summary);
  layout->addWidget(buttons);
  update();
}

QString RangeDialog::path() const { return m_path->text(); }

void RangeDialog::setPath(const QString& path) { m_path->setText(path); }

QString RangeDialog::summary() const { return m_summary ? m_summary->text() : QString(); }

bool RangeDialog::canExport() const { return m_ok && m_ok->isEnabled(); }

void RangeDialog::showSummary(const QString& text, bool isOk) {
  if (!m_summary) return;  // before finishLayout()
  m_summary->setText(text);
  m_ok->setEnabled(isOk);
}

QString RangeDialog::byteText(double bytes) {
  if (bytes >= 1e9) return QString("%1 GB").arg(bytes / 1e9, 0, 'f', 1);
  if (bytes >= 1e6) return QString("%1 MB").arg(bytes / 1e6, 0, 'f', bytes >= 1e8 ? 0 : 1);
  return QString("%1 kB").arg(std::max(1.0, bytes / 1e3), 0, 'f', 0);
}

}  // namespace pneuma::app
