#pragma once
/// @file ParameterPanel.h
/// The parameter panel: breathing frequency, contraction ratios r, gain scales, gut kappa, joint
/// friction, gravity and the posture (a combo box of sim::postureNames()). Each edit is checked with the
/// sim's own validators before anything is applied; an invalid value stays in its field, marked red, with the
/// validator's reason shown under the panel, one line per refused field. While an affect or a pattern drives
/// the breathing, the breath-style fields are disabled and the panel says what drives it.

#include <QWidget>
#include <functional>
#include <memory>
#include <vector>

#include "gui/SimWorker.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QLineEdit;

namespace pneuma::app {

class ParameterPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ParameterPanel(QWidget* parent = nullptr);

  /// Shows `settings` for `model` (may be null), whose own values show where the options leave them unset
  /// (sim::resolveOptions()).
  void setSettings(const RunSettings& settings, std::shared_ptr<const sim::Model> model);
  const RunSettings& settings() const { return m_settings; }

  /// Every refused field's reason, one line each in field order ("<field>: <value> refused: <why>"), or
  /// empty.
  QString refusal() const;
  /// Shows that `driver` (for example "affect 'fear'") drives the breathing instead of the breath style,
  /// whose fields are then disabled; empty: the breath style drives, its fields are editable.
  void setDriver(const QString& driver);
  /// What the panel says drives the breathing (empty: the breath style).
  QString driverText() const;
  /// The field editing the breathing frequency [breaths/min] (for tests and shortcuts).
  QLineEdit* frequencyField() const { return m_fields.front().edit; }
  /// The posture combo box (for tests).
  QComboBox* postureBox() const { return m_posture; }
  /// The field editing the motion magnification of the view [-] (display only, viz::DisplayOptions).
  QLineEdit* magnificationField() const { return m_magnification; }
  /// Shows the view's motion magnification [-].
  void setMagnification(double factor);

 signals:
  /// A valid edit: apply at the next sync point.
  void settingsEdited(const RunSettings& settings);
  /// A valid motion magnification [-] in [viz::kMinMagnification, viz::kMaxMagnification].
  void magnificationEdited(double factor);

 private:
  struct Field {
    QLineEdit* edit = nullptr;
    std::function<double(const RunSettings&)> get;  // value shown, in the field's unit
    std::function<void(RunSettings&, double)> set;  // from the field's unit
  };

  void addField(const QString& label, const QString& unit, const QString& tip,
                std::function<double(const RunSettings&)> get, std::function<void(RunSettings&, double)> set);
  void edited(const Field& field);
  void refuse(QLineEdit* edit, const QString& reason);
  void accept(QLineEdit* edit);
  void showReasons();

  RunSettings m_settings;
  std::shared_ptr<const sim::Model> m_model;
  std::vector<Field> m_fields;
  std::size_t m_styleFieldCount = 0;                      // the first fields edit the breath style
  std::vector<std::pair<QLineEdit*, QString>> m_refused;  // each refused field's reason, in the order refused
  QCheckBox* m_gravity = nullptr;
  QComboBox* m_posture = nullptr;
  QLineEdit* m_magnification = nullptr;
  QLabel* m_reason = nullptr;
  QLabel* m_driver = nullptr;
};

}  // namespace pneuma::app
