#include "gui/ParameterPanel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QLabel>
#include <QLineEdit>
#include <QVBoxLayout>
#include <algorithm>

#include "pneuma/sim/Error.h"
#include "viz/ModelScene.h"

namespace pneuma::app {

namespace {

// scales applied to every muscle group at once (cartilage keeps its own gains)
double muscleScale(const std::array<double, sim::kElementGroupCount>& scales) { return scales[0]; }
void setMuscleScale(std::array<double, sim::kElementGroupCount>& scales, double v) {
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    if (sim::isMuscleGroup(static_cast<sim::ElementGroup>(g))) scales[static_cast<std::size_t>(g)] = v;
}

// a validator's message in a reader's words: without the style's name in front (the panel edits the style in
// play) and with the file format's snake_case keys as words ("breaths_per_minute" -> "breaths per minute")
QString plainReason(const std::string& message) {
  QString text = QString::fromStdString(message);
  if (text.startsWith("breath style '")) {
    const int end = text.indexOf("': ");
    if (end > 0) text = text.mid(end + 3);
  }
  return text.replace('_', ' ');
}

}  // namespace

ParameterPanel::ParameterPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  m_driver = new QLabel;
  m_driver->setWordWrap(true);
  m_driver->hide();
  layout->addWidget(m_driver);
  auto* form = new QFormLayout;
  form->setFieldGrowthPolicy(QFormLayout::ExpandingFieldsGrow);
  layout->addLayout(form);

  addField(
      "Frequency", "breaths/min", "Breathing rate of the breath style (Table 2)",
      [](const RunSettings& s) { return s.style.breathsPerMinute; },
      [](RunSettings& s, double v) { s.style.breathsPerMinute = v; });
  addField(
      "Diaphragm r", "-", "Diaphragm contraction ratio during inhale (Eq. 2)",
      [](const RunSettings& s) { return s.style.diaphragmR; },
      [](RunSettings& s, double v) { s.style.diaphragmR = v; });
  addField(
      "Intercostal r mean", "-", "Mean contraction ratio of the intercostal sinusoids",
      [](const RunSettings& s) { return s.style.intercostalMean; },
      [](RunSettings& s, double v) { s.style.intercostalMean = v; });
  addField(
      "Intercostal r \u00b1", "-", "Amplitude of the intercostal sinusoids (Table 2)",
      [](const RunSettings& s) { return s.style.intercostalAmplitude; },
      [](RunSettings& s, double v) { s.style.intercostalAmplitude = v; });
  m_styleFieldCount = m_fields.size();
  addField(
      "Active gain k_ac \u00d7", "-", "Scale of every muscle's active gain",
      [](const RunSettings& s) { return muscleScale(s.options.step.activeGainScale); },
      [](RunSettings& s, double v) { setMuscleScale(s.options.step.activeGainScale, v); });
  addField(
      "Passive gain k_pe \u00d7", "-", "Scale of every muscle's passive gain and damping",
      [](const RunSettings& s) { return muscleScale(s.options.step.passiveGainScale); },
      [](RunSettings& s, double v) { setMuscleScale(s.options.step.passiveGainScale, v); });
  addField(
      "Gut \u03ba", "kPa", "Bulk modulus of the gut, P = \u03ba (V0/V - 1) (Eq. 4)",
      [this](const RunSettings& s) {
        return m_model ? 1e-3 * sim::resolveOptions(*m_model, s.options).kappa : 0.0;
      },
      [](RunSettings& s, double v) { s.options.step.kappa = 1e3 * v; });
  addField(
      "Joint friction \u03bc \u00d7", "-", "Scale of every joint's friction (Eq. 3)",
      [](const RunSettings& s) { return s.options.step.jointFrictionScale; },
      [](RunSettings& s, double v) { s.options.step.jointFrictionScale = v; });
  addField(
      "Visceral drag \u03b2 \u00d7", "-",
      "Scale of the gut's visceral drag (model gut.drag); 0 lets the gut bounce after each inhale",
      [](const RunSettings& s) { return s.options.step.gutDragScale; },
      [](RunSettings& s, double v) { s.options.step.gutDragScale = v; });
  for (const Field& f : m_fields) {
    auto* label = new QLabel(f.edit->property("label").toString());
    label->setToolTip(f.edit->toolTip());
    form->addRow(label, f.edit);
  }

  m_gravity = new QCheckBox("Gravity");
  m_gravity->setToolTip("Apply the model's gravity to bodies and gut nodes");
  connect(m_gravity, &QCheckBox::toggled, this, [this](bool on) {
    m_settings.options.step.gravity = on;
    emit settingsEdited(m_settings);
  });
  form->addRow(QString(), m_gravity);

  // the names in sim's order; a new posture restarts the run (SimWorker), which settles in it
  m_posture = new QComboBox;
  m_posture->addItems(QString::fromStdString(sim::postureNames()).split(", "));
  m_posture->setToolTip(
      "Direction of gravity relative to the body: upright (seated, the paper's subject), supine "
      "(lying on the back), prone, left- or right-lateral. A change restarts the run.");
  connect(m_posture, &QComboBox::textActivated, this, [this](const QString& name) {
    if (!sim::postureFromName(name.toStdString(), m_settings.options.step.posture)) return;
    emit settingsEdited(m_settings);
  });
  auto* postureLabel = new QLabel("Posture");
  postureLabel->setToolTip(m_posture->toolTip());
  form->addRow(postureLabel, m_posture);

  // the view's motion magnification: display only, never in the run's numbers
  m_magnification = new QLineEdit;
  m_magnification->setToolTip(
      QString("Display only: the view draws every displacement from the end-expiratory "
              "pose this many times larger (%1 to %2); plots and exports keep the real "
              "motion")
          .arg(viz::kMinMagnification)
          .arg(viz::kMaxMagnification));
  setMagnification(viz::kDefaultMagnification);
  connect(m_magnification, &QLineEdit::editingFinished, this, [this] {
    bool isNumber = false;
    const double factor = m_magnification->text().trimmed().toDouble(&isNumber);
    const std::string error =
        isNumber ? viz::magnificationError(factor)
                 : "motion magnification: '" + m_magnification->text().toStdString() + "' is not a number";
    if (!error.empty()) return refuse(m_magnification, QString::fromStdString(error));
    accept(m_magnification);
    emit magnificationEdited(factor);
  });
  auto* magnificationLabel = new QLabel("Motion magnification \u00d7");
  magnificationLabel->setToolTip(m_magnification->toolTip());
  form->addRow(magnificationLabel, m_magnification);

  m_reason = new QLabel;
  m_reason->setWordWrap(true);
  m_reason->setStyleSheet("color: #b00020;");
  layout->addWidget(m_reason);
  layout->addStretch(1);
}

void ParameterPanel::addField(const QString& label, const QString& unit, const QString& tip,
                              std::function<double(const RunSettings&)> get,
                              std::function<void(RunSettings&, double)> set) {
  Field f;
  f.edit = new QLineEdit;
  f.edit->setProperty("label", unit == "-" ? label : QString("%1 [%2]").arg(label, unit));
  f.edit->setToolTip(tip);
  f.get = std::move(get);
  f.set = std::move(set);
  m_fields.push_back(f);
  const std::size_t index = m_fields.size() - 1;
  connect(f.edit, &QLineEdit::editingFinished, this, [this, index] { edited(m_fields[index]); });
}

void ParameterPanel::setSettings(const RunSettings& settings, std::shared_ptr<const sim::Model> model) {
  m_settings = settings;
  m_model = std::move(model);
  for (const Field& f : m_fields) {
    f.edit->setText(QString::number(f.get(m_settings), 'g', 6));
    f.edit->setStyleSheet(QString());
  }
  const QSignalBlocker block(m_gravity);
  m_gravity->setChecked(m_settings.options.step.gravity);
  const QSignalBlocker blockPosture(m_posture);
  m_posture->setCurrentText(sim::postureName(m_settings.options.step.posture));
  m_refused.clear();
  showReasons();
}

void ParameterPanel::setDriver(const QString& driver) {
  for (std::size_t i = 0; i < m_styleFieldCount; ++i) m_fields[i].edit->setEnabled(driver.isEmpty());
  m_driver->setText(driver.isEmpty()
                        ? QString()
                        : QString("The %1 drives the breathing: its pattern sets the rate and depth, "
                                  "so the breath style's fields are off until a style is chosen.")
                              .arg(driver));
  m_driver->setVisible(!driver.isEmpty());
}

QString ParameterPanel::driverText() const { return m_driver->text(); }

void ParameterPanel::setMagnification(double factor) {
  m_magnification->setText(QString::number(factor, 'g', 6));
  m_magnification->setStyleSheet(QString());
}

QString ParameterPanel::refusal() const { return m_reason->text(); }

void ParameterPanel::refuse(QLineEdit* edit, const QString& reason) {
  edit->setStyleSheet("background: #ffd9dc;");
  const auto it =
      std::find_if(m_refused.begin(), m_refused.end(), [edit](const auto& r) { return r.first == edit; });
  if (it != m_refused.end())
    it->second = reason;
  else
    m_refused.emplace_back(edit, reason);
  showReasons();
}

void ParameterPanel::accept(QLineEdit* edit) {
  edit->setStyleSheet(QString());
  m_refused.erase(
      std::remove_if(m_refused.begin(), m_refused.end(), [edit](const auto& r) { return r.first == edit; }),
      m_refused.end());
  showReasons();
}

void ParameterPanel::showReasons() {
  QStringList lines;
  for (const auto& [edit, reason] : m_refused) lines << reason;
  m_reason->setText(lines.join('\n'));
}

void ParameterPanel::edited(const Field& field) {
  bool isNumber = false;
  const double value = field.edit->text().trimmed().toDouble(&isNumber);
  const QString name = field.edit->property("label").toString();
  if (!isNumber) return refuse(field.edit, QString("%1: '%2' is not a number").arg(name, field.edit->text()));
  if (value == field.get(m_settings)) return accept(field.edit);

  // check the candidate with the sim's validators; apply nothing unless it passes
  RunSettings candidate = m_settings;
  field.set(candidate, value);
  try {
    sim::validateBreathStyle(candidate.style);
    sim::validateSimulationOptions(candidate.options);
  } catch (const sim::Error& e) {
    return refuse(field.edit,
                  QString("%1: %2 refused: %3").arg(name, field.edit->text(), plainReason(e.what())));
  }
  accept(field.edit);
  m_settings = candidate;
  emit settingsEdited(m_settings);
}

}  // namespace pneuma::app
