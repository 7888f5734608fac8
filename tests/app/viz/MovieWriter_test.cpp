// viz::MovieWriter: a PNG sequence holds each frame as given (top row first, colours in RGB order), an .ogv
// is an Ogg stream, and a writer dropped before finish() leaves no file behind.
#include "viz/MovieWriter.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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
    vtkNew<vtkPNGReader> reader;
    reader->SetFileName(png.c_str());
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    int dims[3];
    image->GetDimensions(dims);
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

}  // namespace
}  // namespace pneuma
