#include "viz/OffscreenView.h"

#include <vtkImageData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pneuma::viz {

OffscreenView::OffscreenView(vtkRenderer* renderer, int width, int height)
    : m_renderer(renderer), m_width(width), m_height(height) {
  if (width < 1 || height < 1)
    throw std::runtime_error("an off-screen view of " + std::to_string(width) + " x " +
                             std::to_string(height) + " pixels");
  m_home = renderer->GetRenderWindow();
  if (m_home) m_home->RemoveRenderer(renderer);
  m_window = vtkSmartPointer<vtkRenderWindow>::New();
  m_window->SetOffScreenRendering(1);
  m_window->SetMultiSamples(0);
  m_window->SetSize(width, height);
  m_window->AddRenderer(renderer);
}

OffscreenView::~OffscreenView() {
  m_window->RemoveRenderer(m_renderer);
  m_window->Finalize();
  if (m_home) m_home->AddRenderer(m_renderer);
}

std::vector<unsigned char> OffscreenView::render() {
  // rendered and read back as ModelPreview's pictures are (the back buffer of the fresh render)
  m_window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(m_window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkImageData* image = grab->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] != m_width || dims[1] != m_height || image->GetNumberOfScalarComponents() != 3)
    throw std::runtime_error("the off-screen view returned " + std::to_string(dims[0]) + " x " +
                             std::to_string(dims[1]) + " pixels instead of " + std::to_string(m_width) +
                             " x " + std::to_string(m_height));
  // VTK's rows run bottom-up
  const std::size_t row = static_cast<std::size_t>(3 * m_width);
  std::vector<unsigned char> rgb(row * static_cast<std::size_t>(m_height));
  const auto* src = static_cast<const unsigned char*>(image->GetScalarPointer());
  for (int y = 0; y < m_height; ++y)
    std::copy_n(src + row * static_cast<std::size_t>(m_height - 1 - y), row,
                rgb.data() + row * static_cast<std::size_t>(y));
  return rgb;
}

}  // namespace pneuma::viz
