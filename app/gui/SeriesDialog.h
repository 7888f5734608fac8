#pragma once
/// @file SeriesDialog.h
/// File > Export > Run as ParaView series (a RangeDialog): the .pvd file, the stretch of the recording, the
/// stride (every n-th recorded frame), and a summary line with the frame count and the estimated size (one
/// frame's encoded bytes, viz::VtkSeriesWriter::frameBytes(), times the frames) before anything is written.

#include "gui/RangeDialog.h"
#include "viz/VtkSeriesWriter.h"

class QSpinBox;

namespace pneuma::app {

class SeriesDialog : public RangeDialog {
  Q_OBJECT

 public:
  /// @param recordedFrom, recordedTo the recording's span [s];  @param recordedFrames its frames (evenly
  /// spaced)
  /// @param frameBytes the bytes one frame takes on disk (its six .vtp parts)
  SeriesDialog(double recordedFrom, double recordedTo, std::size_t recordedFrames, double frameBytes,
               QWidget* parent = nullptr);

  /// The range and stride chosen.
  viz::SeriesRange range() const;
  /// Frames the export will write.
  int frameCount() const;
  QSpinBox* strideBox() const { return m_stride; }

 protected:
  /// "121 frames (every 5th recorded frame: 12 per second, 0.00 s to 10.00 s), 6 files each, about 410 MB".
  void update() override;

 private:
  double m_recordedFrom, m_recordedTo;  // [s]
  std::size_t m_recordedFrames;
  double m_frameBytes;  // [bytes]
  QSpinBox* m_stride = nullptr;
};

}  // namespace pneuma::app
