#pragma once
/// @file MovieWriter.h
/// Frames of one view written as a movie or a PNG sequence, chosen by the path's suffix (any case):
///   .mp4   H.264 in MP4 (yuv420p, playable everywhere), encoded by Debian's `ffmpeg` through a pipe:
///          `ffmpeg -f rawvideo -pix_fmt rgb24 -video_size WxH -framerate FPS -i pipe:0 -c:v libx264
///          -pix_fmt yuv420p -f mp4 <temporary>`; the program is $PNEUMA_FFMPEG when set, else `ffmpeg` on
///          PATH;
///   .ogv   Ogg Theora (VTK's writer, no external program);
///   other  a PNG sequence: <dir>/<stem>_0000.png, <stem>_0001.png, ...
/// Every file goes to a temporary name (AtomicFile.h); finish() renames them once every frame was written. A
/// writer destroyed unfinished (a cancelled or failed export) stops ffmpeg (SIGKILL) and removes the files
/// it began and nothing else, so a failed export leaves nothing behind.

#include <memory>
#include <string>
#include <vector>

namespace pneuma::viz {

class MovieWriter {
 public:
  enum class Format { Mp4, Ogg, PngSequence };

  /// @param path the movie or the PNG sequence's name;  @param fps frames per second of the movie [1/s].
  /// @throws std::runtime_error for an .mp4 when ffmpeg cannot be found (ffmpegMissingMessage()).
  MovieWriter(std::string path, double fps);
  ~MovieWriter();
  MovieWriter(const MovieWriter&) = delete;
  MovieWriter& operator=(const MovieWriter&) = delete;

  /// The format `path`'s suffix asks for.
  static Format formatOf(const std::string& path);
  Format format() const;
  /// True when the path asks for a movie (.mp4 or .ogv).
  bool isMovie() const;
  /// The file of PNG frame `k` ("<dir>/<stem>_0007.png").
  std::string framePath(int k) const;
  /// Appends one frame: `rgb` holds 3 bytes per pixel, rows from the top, `width` x `height` pixels. A movie
  /// takes the first frame's size, cropped to even numbers (the rule of Theora and of H.264 in yuv420p);
  /// later frames must be at least as large and are cropped to it.
  /// @throws std::runtime_error naming the file when it cannot be written (for an MP4, with ffmpeg's
  /// message).
  void writeFrame(const unsigned char* rgb, int width, int height);
  /// Closes the movie (waits for ffmpeg) and renames every file into place.
  /// @throws std::runtime_error naming the file.
  void finish();
  /// Frames written so far.
  int frameCount() const;

  /// The ffmpeg program an MP4 export runs: $PNEUMA_FFMPEG when set (a path, or a name looked up on PATH),
  /// else `ffmpeg` on PATH; empty when it is not there or not executable.
  static std::string ffmpegProgram();
  /// The message for a missing ffmpeg: what to install, and the formats that work without it.
  static std::string ffmpegMissingMessage();
  /// An estimate of the bytes written for `frames` frames of `width` x `height` pixels in `format`, from
  /// bytes per pixel measured on the default model's 3D view (MovieWriter.cpp); within a factor of two.
  static double estimatedBytes(Format format, int width, int height, int frames);

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace pneuma::viz
