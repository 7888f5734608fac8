#pragma once
/// @file RangeDialog.h
/// What the exports of a stretch of the recording ask first, in one dialog: the file, the range (from, to
/// [s]; all of the recording by default), the export's own fields (added by MovieDialog and SeriesDialog),
/// and a summary line saying what will be written (frames, estimated size) before anything is, with
/// *Export* enabled only when it can be written.

#include <QDialog>
#include <QString>

class QDoubleSpinBox;
class QFormLayout;
class QLabel;
class QLineEdit;
class QPushButton;

namespace pneuma::app {

class RangeDialog : public QDialog {
  Q_OBJECT

 public:
  /// The file to write.
  QString path() const;
  void setPath(const QString& path);
  QDoubleSpinBox* fromBox() const { return m_from; }
  QDoubleSpinBox* toBox() const { return m_to; }
  /// The summary line as shown.
  QString summary() const;
  /// Whether *Export* is enabled (the summary says why not).
  bool canExport() const;
  /// A size in bytes for people: "2.8 MB", "640 kB", "1.3 GB".
  static QString byteText(double bytes);

 protected:
  /// @param recordedFrom, recordedTo the recording's span [s] (the range's bounds and default)
  RangeDialog(const QString& title, const QString& defaultPath, const QString& fileFilter,
              double recordedFrom, double recordedTo, QWidget* parent);
  /// The form the subclass adds its rows to (after File, From and To).
  QFormLayout* form() const { return m_form; }
  /// Puts the summary and the buttons under the rows and computes the summary; the subclass's constructor
  /// calls it last.
  void finishLayout();
  /// Shows `text` as the summary; `isOk` enables *Export*.
  void showSummary(const QString& text, bool isOk);
  /// Recomputes the summary; called whenever a field changes (connect the subclass's fields to it).
  virtual void update() = 0;

 private:
  QFormLayout* m_form = nullptr;
  QLineEdit* m_path = nullptr;
  QDoubleSpinBox* m_from = nullptr;
  QDoubleSpinBox* m_to = nullptr;
  QLabel* m_summary = nullptr;
  QPushButton* m_ok = nullptr;
};

}  // namespace pneuma::app
