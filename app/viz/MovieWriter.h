#pragma once
/// @file MovieWriter.h
/// Frames of one view written as an Ogg Theora movie (a path ending in .ogv) or as a PNG sequence (any other
/// suffix: <dir>/<stem>_0000.png, <stem>_0001.png, ...). Every file goes to a temporary name (AtomicFile.h);
/// finish() renames them once every frame was written, and a writer destroyed unfinished removes them, so a
/// failed export leaves nothing behind.

#include <memory>
#include <string>
#include <vector>

namespace pneuma::viz {

class MovieWriter {
 public:
  /// @param path the .ogv movie or the PNG sequence's name;  @param fps frames per second of the movie [1/s].
  MovieWriter(std::string path, double fps);
  ~MovieWriter();
  MovieWriter(const MovieWriter&) = delete;
  MovieWriter& operator=(const MovieWriter&) = delete;

  /// True when the path asks for a movie (.ogv, any case).
  bool isMovie() const;
  /// The file of PNG frame `k` ("<dir>/<stem>_0007.png").
  std::string framePath(int k) const;
  /// Appends one frame: `rgb` holds 3 bytes per pixel, rows from the top, `width` x `height` pixels. A movie
  /// takes the first frame's size, cropped to even numbers (Theora's rule).
  /// @throws std::runtime_error naming the file when it cannot be written.
  void writeFrame(const unsigned char* rgb, int width, int height);
  /// Closes the movie and renames every file into place. @throws std::runtime_error naming the file.
  void finish();
  /// Frames written so far.
  int frameCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace pneuma::viz
