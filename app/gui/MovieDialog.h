#pragma once
/// @file MovieDialog.h
/// File > Export > Animation of the recording (a RangeDialog): the file (the format by the suffix: .mp4, .ogv
/// or a PNG sequence), the stretch of the recording, the frame size (the 3D view as shown, 640 x 360,
/// 1280 x 720 or 1920 x 1080), the overlays (time stamp; volume panel with a cursor), and a summary line with
/// the frame count and the estimated size before anything is rendered. An MP4 without ffmpeg is refused in
/// the dialog with the reason (viz::MovieWriter::ffmpegMissingMessage()); Ogg and PNG still work.

#include <QSize>
#include <vector>

#include "gui/ExportController.h"
#include "gui/RangeDialog.h"

class QCheckBox;
class QComboBox;

namespace pneuma::app {

class MovieDialog : public RangeDialog {
  Q_OBJECT

 public:
  /// @param recordedFrom, recordedTo the recording's span [s] (the range's bounds and default)
  /// @param shownSize the 3D view's size as shown [px]
  MovieDialog(double recordedFrom, double recordedTo, QSize shownSize, QWidget* parent = nullptr);

  /// The range, size and overlays chosen (25 frames per second).
  ExportController::MovieOptions options() const;
  /// The frame sizes offered after "as shown" [px].
  static const std::vector<QSize>& sizes();

  QComboBox* sizeBox() const { return m_size; }
  QCheckBox* timeStampBox() const { return m_timeStamp; }
  QCheckBox* volumePanelBox() const { return m_volumePanel; }

 protected:
  /// "126 frames (5.00 s at 25 fps), 1280 x 720 px, MP4 (H.264), about 2.8 MB", or why it cannot be written.
  void update() override;

 private:
  QSize m_shownSize;
  QComboBox* m_size = nullptr;
  QCheckBox* m_timeStamp = nullptr;
  QCheckBox* m_volumePanel = nullptr;
};

}  // namespace pneuma::app
