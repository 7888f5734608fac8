#pragma once
/// @file ModelPreview.h
/// Off-screen preview renders of a model directory (VTK; needs an X display).

#include <string>

namespace pneuma::app {

/// Renders `<dir>/preview_front.png` (anterior view) and `<dir>/preview_side.png` (right lateral view)
/// of the model in `dir`: bones, elements coloured by group, and the translucent gut with its
/// diaphragm dome. Returns false and sets `why` when no X display is available (nothing is written).
/// @throws sim::Error when the model or a mesh cannot be read, or a PNG cannot be written.
bool renderModelPreviews(const std::string& dir, std::string& why);

}  // namespace pneuma::app
