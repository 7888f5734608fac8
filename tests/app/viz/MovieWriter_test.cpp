// viz::MovieWriter: a PNG sequence holds each frame as given (top row first, colours in RGB order), an .ogv
// is an Ogg stream, an .mp4 is H.264 with the frames, size and duration given (read back by ffprobe), and a
// writer dropped before finish() stops ffmpeg and leaves no file of its own behind (and every other file).
#include "viz/MovieWriter.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "MovieProbe.h"

namespace pneuma {
namespace {

namespace fs = std::filesystem;

// a w x h frame: red in the top-left pixel, blue in the bottom-left one, green elsewhere, brightness k
std::vector<unsigned char> frame(int w, int h, int k) {
  std::vector<unsigned char> rgb(static_cast<std::size_t>(3 * w * h));
  for (int i = 0; i < w * h; ++i)
    rgb[static_cast<std::size_t>(3 * i + 1)] = static_cast<unsigned char>(100 + k);
  rgb[0] = 255, rgb[1] = 0;
  const std::size_t bottom = static_cast<std::size_t>(3 * w * (h - 1));
  rgb[bottom + 1] = 0, rgb[bottom + 2] = 255;
  return rgb;
}

// a PNG file as VTK image data (rows bottom-up), with its width and height in `dims`
vtkSmartPointer<vtkImageData> readPng(const fs::path& png, int dims[3]) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkSmartPointer<vtkImageData> image = reader->GetOutput();
  image->GetDimensions(dims);
  return image;
}

fs::path freshDir(const std::string& name) {
  const fs::path dir =
      fs::path(testing::TempDir()) / ("pneuma_movie_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(MovieWriter, PngSequenceHoldsEachFrameAsGiven) {
  const fs::path dir = freshDir("png");
  viz::MovieWriter writer((dir / "breath.png").string(), 25.0);
  EXPECT_FALSE(writer.isMovie());
  const int w = 7, h = 5;  // odd sizes are kept for PNG
  for (int k = 0; k < 3; ++k) writer.writeFrame(frame(w, h, k).data(), w, h);
  writer.finish();
  for (int k = 0; k < 3; ++k) {
    const fs::path png = dir / ("breath_000" + std::to_string(k) + ".png");
    ASSERT_TRUE(fs::exists(png)) << png;
    int dims[3];
    const vtkSmartPointer<vtkImageData> image = readPng(png, dims);
    EXPECT_EQ(dims[0], w);
    EXPECT_EQ(dims[1], h);
    // VTK's rows run bottom-up: the top-left pixel is at (0, h - 1)
    EXPECT_EQ(image->GetScalarComponentAsDouble(0, h - 1, 0, 0), 255.0);
    EXPECT_EQ(image->GetScalarComponentAsDouble(0, 0, 0, 2), 255.0);
    EXPECT_EQ(image->GetScalarComponentAsDouble(3, 2, 0, 1), 100.0 + k);
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 3);  // no temporaries
}

TEST(MovieWriter, OgvIsAnOggStreamAndAnUnfinishedWriterLeavesNothing) {
  const fs::path dir = freshDir("ogv");
  {
    viz::MovieWriter writer((dir / "breath.ogv").string(), 25.0);
    EXPECT_TRUE(writer.isMovie());
    for (int k = 0; k < 5; ++k)
      writer.writeFrame(frame(33, 17, 10 * k).data(), 33, 17);  // cropped to 32 x 16
    writer.finish();
  }
  std::ifstream movie(dir / "breath.ogv", std::ios::binary);
  std::string magic(4, '\0');
  movie.read(magic.data(), 4);
  EXPECT_EQ(magic, "OggS");
  {
    viz::MovieWriter dropped((dir / "dropped.ogv").string(), 25.0);
    dropped.writeFrame(frame(32, 16, 0).data(), 32, 16);
    viz::MovieWriter droppedPng((dir / "dropped.png").string(), 25.0);
    droppedPng.writeFrame(frame(32, 16, 0).data(), 32, 16);
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1) << "only breath.ogv";
}

// a w x h frame, red above the middle and blue below it, with a grey bar that moves down by k rows per frame
std::vector<unsigned char> halves(int w, int h, int k) {
  std::vector<unsigned char> rgb(static_cast<std::size_t>(3 * w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char* p = &rgb[static_cast<std::size_t>(3 * (y * w + x))];
      const bool isBar = y >= k % h && y < k % h + 4;
      p[0] = isBar ? 128 : y < h / 2 ? 230 : 20;
      p[1] = isBar ? 128 : 20;
      p[2] = isBar ? 128 : y < h / 2 ? 20 : 230;
    }
  return rgb;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// true when this process has no child left, running or unreaped (ffmpeg was stopped and waited for)
bool hasNoChildProcess() {
  int status = 0;
  return waitpid(-1, &status, WNOHANG) == -1 && errno == ECHILD;
}

// PNEUMA_FFMPEG set for one scope
struct FfmpegOverride {
  explicit FfmpegOverride(const char* program) { setenv("PNEUMA_FFMPEG", program, 1); }
  ~FfmpegOverride() { unsetenv("PNEUMA_FFMPEG"); }
};

TEST(MovieWriter, Mp4IsH264WithTheFramesSizeAndDurationWritten) {
  ASSERT_FALSE(viz::MovieWriter::ffmpegProgram().empty()) << viz::MovieWriter::ffmpegMissingMessage();
  const fs::path dir = freshDir("mp4");
  const int w = 97, h = 63, frames = 50;  // odd: cropped to 96 x 62 (yuv420p)
  {
    viz::MovieWriter writer((dir / "breath.mp4").string(), 25.0);
    EXPECT_EQ(writer.format(), viz::MovieWriter::Format::Mp4);
    for (int k = 0; k < frames; ++k) writer.writeFrame(halves(w, h, k).data(), w, h);
    writer.finish();
  }
  test::expectMp4((dir / "breath.mp4").string(), frames, 96, 62);
  EXPECT_TRUE(hasNoChildProcess());

  // the first frame decoded: red on top and blue below, as given (rows from the top, RGB order)
  const fs::path png = dir / "first.png";
  ASSERT_EQ(std::system(("ffmpeg -v error -i '" + (dir / "breath.mp4").string() + "' -frames:v 1 '" +
                         png.string() + "'")
                            .c_str()),
            0);
  int dims[3];
  const vtkSmartPointer<vtkImageData> image = readPng(png, dims);
  ASSERT_EQ(dims[0], 96);
  const auto at = [&](int x, int yFromTop, int c) {
    return image->GetScalarComponentAsDouble(x, dims[1] - 1 - yFromTop, 0, c);
  };
  EXPECT_GT(at(48, 20, 0), 180.0);  // red in the top half (below the bar)
  EXPECT_LT(at(48, 20, 2), 70.0);
  EXPECT_GT(at(48, 50, 2), 180.0);  // blue in the bottom half
  EXPECT_LT(at(48, 50, 0), 70.0);
  fs::remove(png);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1) << "only breath.mp4";
}

// a cancelled MP4 (the writer destroyed part-way) kills ffmpeg and removes its temporary file, and touches
// nothing else: not an earlier movie of the same name, not another file in the folder
TEST(MovieWriter, UnfinishedMp4StopsFfmpegAndRemovesOnlyItsOwnFile) {
  const fs::path dir = freshDir("mp4cancel");
  { std::ofstream(dir / "breath.mp4") << "an earlier movie"; }
  { std::ofstream(dir / "breath.mp4.tmp-1") << "another program's file"; }
  {
    viz::MovieWriter writer((dir / "breath.mp4").string(), 25.0);
    for (int k = 0; k < 10; ++k) writer.writeFrame(halves(320, 240, k).data(), 320, 240);
  }
  EXPECT_TRUE(hasNoChildProcess()) << "ffmpeg was killed and reaped";
  EXPECT_EQ(slurp(dir / "breath.mp4"), "an earlier movie");
  EXPECT_EQ(slurp(dir / "breath.mp4.tmp-1"), "another program's file");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 2);
}

// without ffmpeg an MP4 is refused at once, saying what to install and what works without it; an ffmpeg
// that fails is an error with its exit, never a crash (SIGPIPE) or a file
TEST(MovieWriter, MissingOrFailingFfmpegIsAClearErrorAndLeavesNothing) {
  const fs::path dir = freshDir("noffmpeg");
  {
    FfmpegOverride missing("/nonexistent/ffmpeg");
    EXPECT_EQ(viz::MovieWriter::ffmpegProgram(), "");
    try {
      viz::MovieWriter writer((dir / "breath.mp4").string(), 25.0);
      ADD_FAILURE() << "an MP4 without ffmpeg was accepted";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("breath.mp4"), std::string::npos) << what;
      EXPECT_NE(what.find("apt install ffmpeg"), std::string::npos) << what;
      EXPECT_NE(what.find(".ogv"), std::string::npos) << what;
    }
    // Ogg needs no ffmpeg
    viz::MovieWriter ogg((dir / "breath.ogv").string(), 25.0);
    ogg.writeFrame(frame(32, 16, 0).data(), 32, 16);
    ogg.finish();
  }
  {
    FfmpegOverride failing("/bin/false");
    EXPECT_THROW(
        {
          viz::MovieWriter writer((dir / "failed.mp4").string(), 25.0);
          for (int k = 0; k < 200; ++k) writer.writeFrame(halves(640, 360, k).data(), 640, 360);
          writer.finish();
        },
        std::runtime_error);
  }
  EXPECT_TRUE(hasNoChildProcess());
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1) << "only breath.ogv";
}

}  // namespace
}  // namespace pneuma
