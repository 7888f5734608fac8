#include "viz/MovieWriter.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkOggTheoraWriter.h>
#include <vtkPNGWriter.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "viz/AtomicFile.h"

namespace pneuma::viz {

namespace fs = std::filesystem;

struct MovieWriter::Impl {
  std::string path;
  double fps = 25.0;  // [1/s]
  bool isMovie = false;
  std::vector<std::string> temporaries;  // written, renamed by finish()
  int frames = 0;
  bool isFinished = false;
  vtkNew<vtkImageData> image;
  vtkNew<vtkOggTheoraWriter> movie;
  int movieWidth = 0, movieHeight = 0;

  // the top-down RGB rows as VTK image data (VTK's rows run bottom-up), `w` x `h` of them
  void load(const unsigned char* rgb, int stride, int w, int h) {
    image->SetDimensions(w, h, 1);
    image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* dst = static_cast<unsigned char*>(image->GetScalarPointer());
    for (int y = 0; y < h; ++y)
      std::copy_n(rgb + static_cast<std::size_t>(stride) * static_cast<std::size_t>(h - 1 - y), 3 * w,
                  dst + static_cast<std::size_t>(3 * w) * static_cast<std::size_t>(y));
    image->Modified();
  }
};

MovieWriter::MovieWriter(std::string path, double fps) : m_impl(std::make_unique<Impl>()) {
  m_impl->path = std::move(path);
  m_impl->fps = fps;
  std::string suffix = fs::path(m_impl->path).extension().string();
  std::transform(suffix.begin(), suffix.end(), suffix.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  m_impl->isMovie = suffix == ".ogv";
}

MovieWriter::~MovieWriter() {
  if (m_impl->isFinished) return;
  if (m_impl->isMovie && m_impl->frames > 0) m_impl->movie->End();
  std::error_code ec;
  for (const std::string& t : m_impl->temporaries) fs::remove(t, ec);
}

bool MovieWriter::isMovie() const { return m_impl->isMovie; }

int MovieWriter::frameCount() const { return m_impl->frames; }

std::string MovieWriter::framePath(int k) const {
  const fs::path p(m_impl->path);
  char number[16];
  std::snprintf(number, sizeof number, "_%04d.png", k);
  return (p.parent_path() / (p.stem().string() + number)).string();
}

void MovieWriter::writeFrame(const unsigned char* rgb, int width, int height) {
  Impl& s = *m_impl;
  const int stride = 3 * width;
  if (s.isMovie) {
    if (s.frames == 0) {
      s.movieWidth = width & ~1;
      s.movieHeight = height & ~1;
      s.temporaries.push_back(temporaryPathFor(s.path));
      s.movie->SetInputData(s.image);
      s.movie->SetFileName(s.temporaries.back().c_str());
      s.movie->SetRate(static_cast<int>(std::lround(s.fps)));
      s.movie->SetQuality(2);
    }
    if (width < s.movieWidth || height < s.movieHeight)
      throw std::runtime_error("cannot write " + s.path + ": frame " + std::to_string(s.frames) +
                               " is smaller than the first");
    s.load(rgb, stride, s.movieWidth, s.movieHeight);
    if (s.frames == 0) s.movie->Start();
    s.movie->Write();
    if (s.movie->GetError()) throw std::runtime_error("the Ogg Theora writer failed on " + s.path);
  } else {
    s.load(rgb, stride, width, height);
    s.temporaries.push_back(temporaryPathFor(framePath(s.frames)));
    vtkNew<vtkPNGWriter> png;
    png->SetInputData(s.image);
    png->SetFileName(s.temporaries.back().c_str());
    png->Write();
    std::error_code ec;
    if (png->GetErrorCode() != 0 || !(fs::file_size(s.temporaries.back(), ec) > 0))
      throw std::runtime_error("cannot write " + framePath(s.frames));
  }
  ++s.frames;
}

void MovieWriter::finish() {
  Impl& s = *m_impl;
  if (s.frames == 0) throw std::runtime_error("cannot write " + s.path + ": no frames");
  if (s.isMovie) {
    s.movie->End();
    commitTemporary(s.temporaries.front(), s.path);
  } else {
    for (int k = 0; k < s.frames; ++k)
      commitTemporary(s.temporaries[static_cast<std::size_t>(k)], framePath(k));
  }
  s.isFinished = true;
}

}  // namespace pneuma::viz
