#include "RenderTestSupport.h"

#include <weft/render/ImageSequenceWriter.h>
#include <weft/render/Png.h>
#include <weft/render/VideoWriter.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace weft::test {
namespace {

// A small image with every byte value represented and a non-trivial alpha channel.
Image testPattern(int width = 37, int height = 23) {
  Image image;
  image.resize(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = image.offset(x, y);
      image.rgba[i] = static_cast<std::uint8_t>(x * 7);
      image.rgba[i + 1] = static_cast<std::uint8_t>(y * 11);
      image.rgba[i + 2] = static_cast<std::uint8_t>((x + y) * 13);
      image.rgba[i + 3] = static_cast<std::uint8_t>(255 - x - y);
    }
  }
  return image;
}

std::filesystem::path freshDir(const std::string& name) {
  const std::filesystem::path dir = outputDir() / name;
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(Png, RoundTripIsExact) {
  const Image image = testPattern();
  const std::filesystem::path dir = freshDir("png-roundtrip");
  std::filesystem::create_directories(dir);
  for (PngCompression compression : {PngCompression::kDefault, PngCompression::kFast}) {
    const std::string path = (dir / "pattern.png").string();
    ASSERT_TRUE(writePng(path, image, compression).ok());
    Result<Image> read = readPng(path);
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read.value(), image);
  }
}

TEST(Png, BadOutputPathNamesThePath) {
  const std::string path = "/nonexistent-weft-dir/sub/frame.png";
  const Status status = writePng(path, testPattern());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find(path), std::string::npos) << status.error().message;
  EXPECT_NE(status.error().message.find("No such file or directory"), std::string::npos) << status.error().message;
}

TEST(Png, EmptyImageIsAnError) {
  const std::string path = (outputDir() / "empty.png").string();
  const Status status = writePng(path, Image{});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find(path), std::string::npos);
}

TEST(Png, ReadingANonPngNamesThePath) {
  const std::filesystem::path path = outputDir() / "not-a-png.png";
  std::ofstream(path) << "hello";
  Result<Image> read = readPng(path.string());
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().message.find(path.string()), std::string::npos) << read.error().message;
  Result<Image> missing = readPng("/nonexistent-weft-dir/x.png");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("/nonexistent-weft-dir/x.png"), std::string::npos);
}

TEST(ImageSequenceWriter, WritesNumberedFramesInOrder) {
  const std::filesystem::path dir = freshDir("sequence");
  Result<ImageSequenceWriter> writer = ImageSequenceWriter::open(dir.string(), {.queueCapacity = 2});
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  std::vector<Image> frames;
  for (int i = 0; i < 6; ++i) {
    frames.push_back(testPattern(16 + i, 9));
    ASSERT_TRUE(writer->write(frames.back()).ok());
  }
  ASSERT_TRUE(writer->finish().ok());
  EXPECT_EQ(writer->framesQueued(), 6);
  EXPECT_EQ(writer->framePath(3), (dir / "frame_00003.png").string());
  for (int i = 0; i < 6; ++i) {
    Result<Image> read = readPng(writer->framePath(i));
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read.value(), frames[i]) << "frame " << i;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "frame_00006.png"));
}

TEST(ImageSequenceWriter, UnwritableDirectoryIsAnError) {
  const std::filesystem::path file = outputDir() / "a-plain-file";
  std::ofstream(file) << "x";
  Result<ImageSequenceWriter> writer = ImageSequenceWriter::open((file / "frames").string());
  ASSERT_FALSE(writer.ok());
  EXPECT_NE(writer.error().message.find(file.string()), std::string::npos) << writer.error().message;
}

// ffmpeg may or may not be installed: without it the writer is a disabled no-op with a notice;
// with it, frames become a non-empty file. Either way nothing fails.
TEST(VideoWriter, EncodesWithFfmpegOrSkipsWithANotice) {
  const std::filesystem::path path = outputDir() / "video.mp4";
  std::filesystem::remove(path);
  Result<VideoWriter> writer = VideoWriter::open(path.string(), {.width = 64, .height = 48, .fps = 30});
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(writer->write(testPattern(64, 48)).ok());
  const Status finished = writer->finish();
  ASSERT_TRUE(finished.ok()) << finished.error().message;
  if (writer->enabled()) {
    EXPECT_EQ(writer->framesWritten(), 10);
    EXPECT_GT(std::filesystem::file_size(path), 0u);
  } else {
    EXPECT_EQ(writer->notice(), "ffmpeg not found; skipping video (apt-get install ffmpeg)");
    EXPECT_EQ(writer->framesWritten(), 0);
    EXPECT_FALSE(std::filesystem::exists(path));
  }
}

TEST(VideoWriter, MissingProgramIsANoticeNotAnError) {
  Result<VideoWriter> writer =
      VideoWriter::open((outputDir() / "never.mp4").string(), {.width = 64, .height = 48, .ffmpeg = "weft-no-such-ffmpeg"});
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  EXPECT_FALSE(writer->enabled());
  EXPECT_EQ(writer->notice(), "ffmpeg not found; skipping video (apt-get install ffmpeg)");
  EXPECT_TRUE(writer->write(testPattern(64, 48)).ok());
  EXPECT_TRUE(writer->finish().ok());
}

TEST(VideoWriter, OddSizeIsRejected) {
  Result<VideoWriter> writer = VideoWriter::open((outputDir() / "odd.mp4").string(), {.width = 63, .height = 48});
  ASSERT_FALSE(writer.ok());
  EXPECT_NE(writer.error().message.find("even"), std::string::npos);
}

}  // namespace
}  // namespace weft::test
