// How sources say their colour was sampled (capture::ChromaSampling): from a JPEG's frame
// header, from the decoder's pixel format of real files, and per frame from each source
// (an image sequence's JPEG files each from their own header).
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "lumar/capture/chroma_sampling.h"
#include "lumar/capture/image_sequence_source.h"
#include "lumar/capture/recording_reader.h"
#include "lumar/capture/video_file_source.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {

constexpr std::uint32_t fourcc(const char (&s)[5]) {
  return std::uint32_t(std::uint8_t(s[0])) | std::uint32_t(std::uint8_t(s[1])) << 8 |
         std::uint32_t(std::uint8_t(s[2])) << 16 | std::uint32_t(std::uint8_t(s[3])) << 24;
}

// The offset of the first component's sampling byte in a baseline JPEG's frame header.
std::size_t luma_sampling_at(const std::vector<std::uint8_t>& jpeg) {
  for (std::size_t i = 2; i + 1 < jpeg.size(); ++i)
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xC0) return i + 2 + 2 + 6 + 1;  // marker, length, header, id
  ADD_FAILURE() << "no SOF0";
  return 0;
}

TEST(ChromaSampling, ReadsAJpegsFrameHeader) {
  const cv::Mat image(48, 64, CV_8UC3, cv::Scalar(20, 120, 200));
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
  EXPECT_EQ(chroma_sampling_of_jpeg(jpeg), (ChromaSampling{2, 2})) << "libjpeg's default: 4:2:0";
  // The luma's sampling factors (horizontal << 4 | vertical) against the chroma's 1×1.
  const std::size_t at = luma_sampling_at(jpeg);
  ASSERT_EQ(jpeg[at], 0x22);
  jpeg[at] = 0x21;
  EXPECT_EQ(chroma_sampling_of_jpeg(jpeg), (ChromaSampling{2, 1})) << "4:2:2";
  jpeg[at] = 0x11;
  EXPECT_EQ(chroma_sampling_of_jpeg(jpeg), (ChromaSampling{1, 1})) << "4:4:4";

  cv::Mat grey;
  cv::extractChannel(image, grey, 0);
  cv::imencode(".jpg", grey, jpeg);
  EXPECT_EQ(chroma_sampling_of_jpeg(jpeg), (ChromaSampling{1, 1})) << "one component";
  const std::vector<std::uint8_t> torn{0xFF, 0xD8, 0xFF, 0xC0, 0x00, 0x40}, junk{1, 2, 3};
  EXPECT_EQ(chroma_sampling_of_jpeg(torn), (ChromaSampling{1, 1}));
  EXPECT_EQ(chroma_sampling_of_jpeg(junk), (ChromaSampling{1, 1}));
  EXPECT_EQ(chroma_sampling_of_jpeg({}), (ChromaSampling{1, 1}));
}

TEST(ChromaSampling, NamesFfmpegsPixelFormats) {
  EXPECT_EQ(chroma_sampling_of_pixel_format(fourcc("I420")), (ChromaSampling{2, 2}));
  EXPECT_EQ(chroma_sampling_of_pixel_format(fourcc("NV12")), (ChromaSampling{2, 2}));
  EXPECT_EQ(chroma_sampling_of_pixel_format(fourcc("Y42B")), (ChromaSampling{2, 1}));
  EXPECT_EQ(chroma_sampling_of_pixel_format(fourcc("YUY2")), (ChromaSampling{2, 1}));
  EXPECT_EQ(chroma_sampling_of_pixel_format(fourcc("444P")), (ChromaSampling{1, 1}));
  EXPECT_EQ(chroma_sampling_of_pixel_format(0), (ChromaSampling{1, 1}));
}

TEST(ChromaSampling, FramesCarryTheirSourcesSampling) {
  Frame f;
  // vtest.avi is DivX (4:2:0); tree.avi Cinepak, which FFmpeg decodes to RGB.
  VideoFileSource vtest(test::shared_dir() / "data" / "video" / "vtest.avi");
  ASSERT_TRUE(vtest.read(f));
  EXPECT_EQ(f.chroma, (ChromaSampling{2, 2}));
  VideoFileSource tree(test::shared_dir() / "data" / "video" / "tree.avi");
  ASSERT_TRUE(tree.read(f));
  EXPECT_EQ(f.chroma, (ChromaSampling{1, 1}));
  // The sample recording's MJPEG segments, as a replay reads them.
  const auto frames = RecordingReader(test::source_dir() / "recordings" / "orbit").open_frames();
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(frames->read(f));
    EXPECT_EQ(f.chroma, (ChromaSampling{2, 2})) << "frame " << k;
  }
}

TEST(ChromaSampling, ImageSequencesTakeEachJpegsOwn) {
  const test::Scratch scratch("chroma_image_sequence");
  cv::Mat image(48, 64, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
  const auto write = [&](const char* name, const std::vector<std::uint8_t>& bytes) {
    std::ofstream(scratch.dir / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  };
  write("frame-1.jpg", jpeg);  // libjpeg's 4:2:0
  cv::imwrite((scratch.dir / "frame-2.png").string(), image);
  jpeg[luma_sampling_at(jpeg)] = 0x21;  // the same picture's header made 4:2:2
  write("frame-3.JPEG", jpeg);
  ImageSequenceSource source({scratch.dir.string(), {}, 10.0});
  const std::vector<ChromaSampling> expected{{2, 2}, {1, 1}, {2, 1}};
  Frame f;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    ASSERT_TRUE(source.read(f));
    EXPECT_EQ(f.chroma, expected[k]) << source.files()[k];
    // Decoded as cv::imread decodes the file.
    EXPECT_EQ(cv::norm(f.image, cv::imread(source.files()[k].string(), cv::IMREAD_COLOR), cv::NORM_INF), 0.0)
        << source.files()[k];
  }
  EXPECT_FALSE(source.read(f));
}

}  // namespace
}  // namespace lumar::capture
