#pragma once
// What ffprobe (Debian's ffmpeg package) reads from a movie file: container, codec, pixel format, size, the
// frames it decodes and the duration. Shared by the movie tests of viz, the app and its command line.

#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

namespace pneuma::test {

struct MovieProbe {
  std::string container;    ///< e.g. "mov,mp4,m4a,3gp,3g2,mj2"
  std::string codec;        ///< e.g. "h264"
  std::string pixelFormat;  ///< e.g. "yuv420p"
  int width = 0, height = 0;
  int frames = 0;         ///< frames decoded (ffprobe -count_frames)
  double duration = 0.0;  ///< [s] the container's duration
  std::string error;      ///< why it could not be read (empty when read)
};

/// Runs ffprobe on `path`; a missing ffprobe or an unreadable file gives `error`.
inline MovieProbe probeMovie(const std::string& path) {
  MovieProbe p;
  const std::string command =
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,pix_fmt,width,height,nb_read_frames:format=duration,format_name -of json '" +
      path + "' 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    p.error = "cannot run ffprobe";
    return p;
  }
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = pclose(pipe);
  if (status != 0) {
    p.error = "ffprobe failed (status " + std::to_string(status) + "): " + out;
    return p;
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(out);
    const nlohmann::json& s = j.at("streams").at(0);
    p.codec = s.value("codec_name", "");
    p.pixelFormat = s.value("pix_fmt", "");
    p.width = s.value("width", 0);
    p.height = s.value("height", 0);
    p.frames = std::stoi(s.value("nb_read_frames", "0"));
    p.container = j.at("format").value("format_name", "");
    p.duration = std::stod(j.at("format").value("duration", "0"));
  } catch (const std::exception& e) {
    p.error = std::string("cannot read ffprobe's answer: ") + e.what() + ": " + out;
  }
  return p;
}

/// Expects `path` to be an H.264 MP4 (yuv420p) of `frames` frames of `width` x `height` pixels lasting
/// frames / `fps` seconds (within 0.05 s), as ffprobe reads it.
inline void expectMp4(const std::string& path, int frames, int width, int height, double fps = 25.0) {
  const MovieProbe probe = probeMovie(path);
  ASSERT_EQ(probe.error, "") << path;
  EXPECT_NE(probe.container.find("mp4"), std::string::npos) << probe.container;
  EXPECT_EQ(probe.codec, "h264");
  EXPECT_EQ(probe.pixelFormat, "yuv420p");
  EXPECT_EQ(probe.frames, frames);
  EXPECT_EQ(probe.width, width);
  EXPECT_EQ(probe.height, height);
  EXPECT_NEAR(probe.duration, frames / fps, 0.05);  // [s]
}

}  // namespace pneuma::test
