#include "viz/MovieWriter.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkOggTheoraWriter.h>
#include <vtkPNGWriter.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "viz/AtomicFile.h"

extern char** environ;

namespace pneuma::viz {

namespace fs = std::filesystem;

namespace {

// bytes per pixel per frame, measured on the default model's 3D view (calm breathing from 8 to 14 s, motion
// x5, 25 fps, `pneuma --movie`): MP4 0.0050 at 640 x 360 and at 1280 x 720 with both overlays, 0.0037 at
// 1920 x 1080; Ogg 0.023 and PNG 0.14 at 1280 x 720. H.264 at CRF 20 and Theora at quality 2 store mostly the
// motion; a PNG holds every pixel
constexpr double kMp4BytesPerPixel = 0.0045;
constexpr double kOggBytesPerPixel = 0.023;
constexpr double kPngBytesPerPixel = 0.14;

constexpr std::size_t kErrorTail = 2000;  // ffmpeg's last messages kept for an error [bytes]
constexpr int kFinishWaitMs = 60000;      // [ms] at most between two messages while ffmpeg finishes

// `name` looked up on PATH (or taken as is when it holds a '/'); empty when not an executable file
std::string findProgram(const std::string& name) {
  const auto isExecutable = [](const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
  };
  if (name.find('/') != std::string::npos) return isExecutable(name) ? name : std::string();
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
  std::size_t from = 0;
  while (from <= dirs.size()) {
    const std::size_t to = std::min(dirs.find(':', from), dirs.size());
    const fs::path candidate = fs::path(to > from ? dirs.substr(from, to - from) : ".") / name;
    if (isExecutable(candidate)) return candidate.string();
    from = to + 1;
  }
  return {};
}

// ffmpeg encoding raw RGB frames from a pipe into an MP4 file; killed and reaped when destroyed unfinished
class FfmpegPipe {
 public:
  FfmpegPipe(const std::string& program, const std::string& output, int width, int height, double fps) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", fps);
    const std::vector<std::string> args = {program,
                                           "-hide_banner",
                                           "-nostats",
                                           "-loglevel",
                                           "error",
                                           "-f",
                                           "rawvideo",
                                           "-pix_fmt",
                                           "rgb24",
                                           "-video_size",
                                           std::to_string(width) + "x" + std::to_string(height),
                                           "-framerate",
                                           rate,
                                           "-i",
                                           "pipe:0",
                                           "-an",
                                           "-c:v",
                                           "libx264",
                                           "-preset",
                                           "veryfast",
                                           "-crf",
                                           "20",
                                           "-pix_fmt",
                                           "yuv420p",
                                           "-movflags",
                                           "+faststart",
                                           "-f",
                                           "mp4",
                                           "-y",
                                           output};
    int input[2], errors[2];
    if (::pipe2(input, O_CLOEXEC) != 0)
      throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    if (::pipe2(errors, O_CLOEXEC) != 0) {
      ::close(input[0]), ::close(input[1]);
      throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, input[0], 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, errors[1], 2);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int error = posix_spawn(&m_pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(input[0]);
    ::close(errors[1]);
    if (error != 0) {
      ::close(input[1]), ::close(errors[0]);
      throw std::runtime_error("cannot start " + program + ": " + std::strerror(error));
    }
    m_input = input[1];
    m_errors = errors[0];
    ::fcntl(m_errors, F_SETFL, ::fcntl(m_errors, F_GETFL) | O_NONBLOCK);
  }

  ~FfmpegPipe() {
    closeInput();
    if (m_pid > 0) {
      ::kill(m_pid, SIGKILL);
      int status = 0;
      while (::waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    if (m_errors >= 0) ::close(m_errors);
  }
  FfmpegPipe(const FfmpegPipe&) = delete;
  FfmpegPipe& operator=(const FfmpegPipe&) = delete;

  /// Writes `n` bytes to ffmpeg's input; false when ffmpeg has stopped reading (it exited).
  bool write(const unsigned char* bytes, std::size_t n) {
    // a closed pipe gives EPIPE here instead of a SIGPIPE that would end the whole program
    sigset_t pipeSignal, old;
    sigemptyset(&pipeSignal);
    sigaddset(&pipeSignal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipeSignal, &old);
    bool isOk = true;
    while (n > 0) {
      const ssize_t k = ::write(m_input, bytes, n);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) {
        isOk = false;
        break;
      }
      bytes += k;
      n -= static_cast<std::size_t>(k);
      drainErrors(false);
    }
    if (!isOk) {
      const timespec zero{0, 0};
      sigtimedwait(&pipeSignal, nullptr, &zero);  // the pending SIGPIPE, if any
    }
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    return isOk;
  }

  /// Closes ffmpeg's input and waits for it: its exit code (-1: killed by a signal).
  int finish() {
    closeInput();
    drainErrors(true);
    int status = 0;
    while (::waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
    }
    m_pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  /// ffmpeg's last messages on one line.
  std::string messages() {
    drainErrors(false);
    std::string text = m_messages;
    std::replace(text.begin(), text.end(), '\n', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
  }

 private:
  void closeInput() {
    if (m_input >= 0) ::close(m_input);
    m_input = -1;
  }
  // reads what ffmpeg wrote to its stderr (until end of file when `isToEnd`), keeping the tail
  void drainErrors(bool isToEnd) {
    char buffer[4096];
    while (m_errors >= 0) {
      if (isToEnd) {
        pollfd p{m_errors, POLLIN, 0};
        if (::poll(&p, 1, kFinishWaitMs) == 0) break;  // ffmpeg is still busy: do not wait for ever here
      }
      const ssize_t k = ::read(m_errors, buffer, sizeof buffer);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) {
        if (k == 0 || !isToEnd || errno != EAGAIN) break;
        continue;
      }
      m_messages.append(buffer, static_cast<std::size_t>(k));
      if (m_messages.size() > kErrorTail) m_messages.erase(0, m_messages.size() - kErrorTail);
    }
  }

  pid_t m_pid = -1;
  int m_input = -1;   // ffmpeg's stdin (the frames)
  int m_errors = -1;  // ffmpeg's stderr
  std::string m_messages;
};

}  // namespace

struct MovieWriter::Impl {
  std::string path;
  double fps = 25.0;  // [1/s]
  Format format = Format::PngSequence;
  std::string ffmpeg;                    // the program, for an MP4
  std::vector<std::string> temporaries;  // written, renamed by finish()
  int frames = 0;
  bool isFinished = false;
  vtkNew<vtkImageData> image;
  vtkNew<vtkOggTheoraWriter> ogg;
  std::unique_ptr<FfmpegPipe> mp4;
  std::vector<unsigned char> cropped;  // one MP4 frame at the movie's size
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

  void writeMp4(const unsigned char* rgb, int stride) {
    if (frames == 0) {
      temporaries.push_back(temporaryPathFor(path));
      mp4 = std::make_unique<FfmpegPipe>(ffmpeg, temporaries.back(), movieWidth, movieHeight, fps);
    }
    const std::size_t row = static_cast<std::size_t>(3 * movieWidth);
    cropped.resize(row * static_cast<std::size_t>(movieHeight));
    for (int y = 0; y < movieHeight; ++y)
      std::copy_n(rgb + static_cast<std::size_t>(stride) * static_cast<std::size_t>(y), row,
                  cropped.data() + row * static_cast<std::size_t>(y));
    if (!mp4->write(cropped.data(), cropped.size()))
      throw std::runtime_error("cannot write " + path + ": ffmpeg stopped at frame " +
                               std::to_string(frames) + ": " + mp4->messages());
  }
};

MovieWriter::MovieWriter(std::string path, double fps) : m_impl(std::make_unique<Impl>()) {
  m_impl->path = std::move(path);
  m_impl->fps = fps;
  m_impl->format = formatOf(m_impl->path);
  if (m_impl->format == Format::Mp4) {
    m_impl->ffmpeg = ffmpegProgram();
    if (m_impl->ffmpeg.empty())
      throw std::runtime_error("cannot write " + m_impl->path + ": " + ffmpegMissingMessage());
  }
}

MovieWriter::~MovieWriter() {
  if (m_impl->isFinished) return;
  if (m_impl->format == Format::Ogg && m_impl->frames > 0) m_impl->ogg->End();
  m_impl->mp4.reset();  // kills ffmpeg before its output is removed
  std::error_code ec;
  for (const std::string& t : m_impl->temporaries) fs::remove(t, ec);
}

MovieWriter::Format MovieWriter::formatOf(const std::string& path) {
  std::string suffix = fs::path(path).extension().string();
  std::transform(suffix.begin(), suffix.end(), suffix.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (suffix == ".mp4") return Format::Mp4;
  if (suffix == ".ogv") return Format::Ogg;
  return Format::PngSequence;
}

MovieWriter::Format MovieWriter::format() const { return m_impl->format; }

bool MovieWriter::isMovie() const { return m_impl->format != Format::PngSequence; }

int MovieWriter::frameCount() const { return m_impl->frames; }

std::string MovieWriter::ffmpegProgram() {
  const char* chosen = std::getenv("PNEUMA_FFMPEG");
  return findProgram(chosen && *chosen ? chosen : "ffmpeg");
}

std::string MovieWriter::ffmpegMissingMessage() {
  const char* chosen = std::getenv("PNEUMA_FFMPEG");
  const std::string which = chosen && *chosen ? std::string("'") + chosen + "' (PNEUMA_FFMPEG)" : "ffmpeg";
  return "MP4 export needs " + which +
         ", which was not found: install Debian's ffmpeg (sudo apt install ffmpeg), or export an Ogg "
         "Theora movie (.ogv) or a PNG sequence, which need nothing else";
}

double MovieWriter::estimatedBytes(Format format, int width, int height, int frames) {
  const double pixels = static_cast<double>(width) * height * frames;
  switch (format) {
    case Format::Mp4:
      return kMp4BytesPerPixel * pixels;
    case Format::Ogg:
      return kOggBytesPerPixel * pixels;
    case Format::PngSequence:
      break;
  }
  return kPngBytesPerPixel * pixels;
}

std::string MovieWriter::framePath(int k) const {
  const fs::path p(m_impl->path);
  char number[16];
  std::snprintf(number, sizeof number, "_%04d.png", k);
  return (p.parent_path() / (p.stem().string() + number)).string();
}

void MovieWriter::writeFrame(const unsigned char* rgb, int width, int height) {
  Impl& s = *m_impl;
  const int stride = 3 * width;
  if (s.format == Format::PngSequence) {
    s.load(rgb, stride, width, height);
    s.temporaries.push_back(temporaryPathFor(framePath(s.frames)));
    vtkNew<vtkPNGWriter> png;
    png->SetInputData(s.image);
    png->SetFileName(s.temporaries.back().c_str());
    png->Write();
    std::error_code ec;
    if (png->GetErrorCode() != 0 || !(fs::file_size(s.temporaries.back(), ec) > 0))
      throw std::runtime_error("cannot write " + framePath(s.frames));
    ++s.frames;
    return;
  }
  if (s.frames == 0) {
    s.movieWidth = width & ~1;
    s.movieHeight = height & ~1;
    if (s.movieWidth < 2 || s.movieHeight < 2)
      throw std::runtime_error("cannot write " + s.path + ": a frame of " + std::to_string(width) + " x " +
                               std::to_string(height) + " pixels is too small for a movie");
  }
  if (width < s.movieWidth || height < s.movieHeight)
    throw std::runtime_error("cannot write " + s.path + ": frame " + std::to_string(s.frames) +
                             " is smaller than the first");
  if (s.format == Format::Mp4) {
    s.writeMp4(rgb, stride);
  } else {
    if (s.frames == 0) {
      s.temporaries.push_back(temporaryPathFor(s.path));
      s.ogg->SetInputData(s.image);
      s.ogg->SetFileName(s.temporaries.back().c_str());
      s.ogg->SetRate(static_cast<int>(std::lround(s.fps)));
      s.ogg->SetQuality(2);
    }
    s.load(rgb, stride, s.movieWidth, s.movieHeight);
    if (s.frames == 0) s.ogg->Start();
    s.ogg->Write();
    if (s.ogg->GetError()) throw std::runtime_error("the Ogg Theora writer failed on " + s.path);
  }
  ++s.frames;
}

void MovieWriter::finish() {
  Impl& s = *m_impl;
  if (s.frames == 0) throw std::runtime_error("cannot write " + s.path + ": no frames");
  if (s.format == Format::Mp4) {
    const int code = s.mp4->finish();
    const std::string messages = s.mp4->messages();
    s.mp4.reset();
    std::error_code ec;
    if (code != 0 || !(fs::file_size(s.temporaries.front(), ec) > 0))
      throw std::runtime_error("cannot write " + s.path + ": ffmpeg failed (exit " + std::to_string(code) +
                               (messages.empty() ? std::string(")") : "): " + messages));
    commitTemporary(s.temporaries.front(), s.path);
  } else if (s.format == Format::Ogg) {
    s.ogg->End();
    commitTemporary(s.temporaries.front(), s.path);
  } else {
    for (int k = 0; k < s.frames; ++k)
      commitTemporary(s.temporaries[static_cast<std::size_t>(k)], framePath(k));
  }
  s.isFinished = true;
}

}  // namespace pneuma::viz
