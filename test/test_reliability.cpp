// SPDX-License-Identifier: BSD-3-Clause
// Bad input through the apps: every case checks the exit code, that the message names the
// file, and that a file already at an output path is untouched (issue 17). The fixtures
// are made here: a small synthetic sequence, then one thing broken per case.
#include <dynvo/io/trajectory_io.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/synthetic_sequence.h"
#include "support/temp_dir.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace {

namespace fs = std::filesystem;
using dynvo::test::CommandResult;
using dynvo::test::readText;
using dynvo::test::runCommand;
using dynvo::test::TempDir;
using dynvo::test::writeText;

const std::string ODOMETRY = DYNVO_ODOMETRY_BIN;
const std::string SEGMENT = DYNVO_SEGMENT_BIN;
const std::string EVALUATE = DYNVO_EVALUATE_BIN;
const std::string SCENE_FLOW = DYNVO_SCENE_FLOW_BIN;

/// What a pre-existing output file holds; it must still hold it after a refused run.
const std::string KEEP = "pre-existing output, must not change\n";

class Reliability : public ::testing::Test {
protected:
  static void SetUpTestSuite()
  {
    sequence_ = new dynvo::test::SyntheticSequence("static_one", FRAMES, 160, 120);
  }

  static void TearDownTestSuite() { delete sequence_; }

  /// A private copy of the sequence that a case may break.
  std::string copy() const
  {
    const std::string seq = dir_.file("seq");
    fs::copy(sequence_->path(), seq, fs::copy_options::recursive);
    return seq;
  }

  /// The k-th file (0-based) listed in an index file of a sequence.
  static std::string listed(const std::string& seq, const std::string& index, int k)
  {
    std::ifstream in(seq + "/" + index);
    std::string line;
    for (int entry = -1; std::getline(in, line);) {
      if (line.empty() || line[0] == '#')
        continue;
      if (++entry == k)
        return seq + "/" + line.substr(line.find(' ') + 1);
    }
    return "";
  }

  /// A file holding KEEP at the given name in the test's folder.
  std::string existing(const std::string& name) const
  {
    writeText(dir_.file(name), KEEP);
    return dir_.file(name);
  }

  static constexpr int FRAMES = 12;
  static dynvo::test::SyntheticSequence* sequence_;
  TempDir dir_;
};

dynvo::test::SyntheticSequence* Reliability::sequence_ = nullptr;

/// The exit code and the file named in the message; the first stderr line is the error.
void
expectFailure(const CommandResult& result, int code, const std::string& named)
{
  EXPECT_EQ(result.exit_code, code) << result.err;
  EXPECT_EQ(result.err.rfind("Error: ", 0), 0u) << result.err;
  EXPECT_NE(result.err.find(named), std::string::npos) << result.err;
}

/// Exit 2 before any frame: no summary line, nothing written.
void
expectRefusedUpFront(const CommandResult& result, const std::string& named)
{
  expectFailure(result, 2, named);
  EXPECT_EQ(result.out.find("frames="), std::string::npos) << result.out;
}

/// The 7th frame has another size (defect 1): it is reported and flagged lost, the run goes
/// on and writes every output.
TEST_F(Reliability, SizeChangeMidRunIsReportedAndTheRunGoesOn)
{
  const std::string seq = copy();
  cv::imwrite(listed(seq, "rgb.txt", 6),
              cv::Mat(120, 200, CV_8UC3, cv::Scalar(9, 9, 9)));
  cv::imwrite(listed(seq, "depth.txt", 6),
              cv::Mat(120, 200, CV_16UC1, cv::Scalar(5000)));
  const auto result = runCommand(
      ODOMETRY + " -tum_dir " + seq + " -out " + dir_.file("t.txt") + " -labels_dir " +
      dir_.file("labels") + " -objects " + dir_.file("o.txt"));
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("frame size changed"), std::string::npos) << result.err;
  EXPECT_EQ(dynvo::readTrajectory(dir_.file("t.txt")).size(),
            static_cast<std::size_t>(FRAMES));
  // The skipped frame has no image to label.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_.file("labels")),
                          fs::directory_iterator()),
            FRAMES - 1);
  EXPECT_TRUE(fs::exists(dir_.file("o.txt")));
  EXPECT_FALSE(fs::exists(dir_.file("o.txt.partial")));

  // dynvo_segment runs the same pipeline: it reports the frame and goes on the same way.
  const auto segment =
      runCommand(SEGMENT + " -tum_dir " + seq + " -out_dir " + dir_.file("masks") +
                 " -objects " + dir_.file("s.txt"));
  EXPECT_EQ(segment.exit_code, 0) << segment.err;
  EXPECT_NE(segment.err.find("frame size changed"), std::string::npos) << segment.err;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_.file("masks")),
                          fs::directory_iterator()),
            FRAMES - 1);
  EXPECT_TRUE(fs::exists(dir_.file("s.txt")));
  EXPECT_FALSE(fs::exists(dir_.file("s.txt.partial")));
}

/// No output may be, or lie inside, anything the run reads (defect 2).
TEST_F(Reliability, OutputsOverInputsAreRefused)
{
  const std::string seq = sequence_->path();
  const std::string groundtruth = readText(seq + "/groundtruth.txt");
  const std::string rgb = listed(seq, "rgb.txt", 0);
  const std::string first_rgb = readText(rgb);
  const std::string run = ODOMETRY + " -tum_dir " + seq;
  expectRefusedUpFront(runCommand(run + " -out " + seq + "/groundtruth.txt"),
                       seq + "/groundtruth.txt: is an input");
  expectRefusedUpFront(runCommand(run + " -out " + seq + "/rgb.txt"), seq + "/rgb.txt");
  expectRefusedUpFront(runCommand(run + " -labels_dir " + seq + "/rgb"), seq + "/rgb");
  expectRefusedUpFront(runCommand(run + " -objects " + seq + "/rgb/objects.txt"),
                       "inside the input folder");
  // The same folder reached through a symbolic link.
  fs::create_directory_symlink(seq + "/depth", dir_.file("link"));
  expectRefusedUpFront(runCommand(run + " -labels_dir " + dir_.file("link")),
                       dir_.file("link"));
  EXPECT_EQ(readText(seq + "/groundtruth.txt"), groundtruth);
  EXPECT_EQ(readText(rgb), first_rgb);

  const std::string config = dir_.file("c.yaml");
  ASSERT_EQ(runCommand(ODOMETRY + " -write_config " + config).exit_code, 0);
  const std::string written = readText(config);
  expectRefusedUpFront(
      runCommand(run + " -config " + config + " -write_config " + config), config);
  EXPECT_EQ(readText(config), written);
  expectRefusedUpFront(
      runCommand(SEGMENT + " -tum_dir " + seq + " -out_dir " + seq + "/depth"),
      seq + "/depth");
  expectRefusedUpFront(runCommand(SCENE_FLOW + " -tum_dir " + seq + " -frame 1 -out " +
                                  seq + "/depth.txt"),
                       seq + "/depth.txt");
  // The ground truth is part of the recording even for an app that does not read it.
  expectRefusedUpFront(runCommand(SEGMENT + " -tum_dir " + seq + " -out_dir " +
                                  dir_.file("masks") + " -objects " + seq +
                                  "/groundtruth.txt"),
                       seq + "/groundtruth.txt");
  EXPECT_EQ(readText(seq + "/groundtruth.txt"), groundtruth);
  EXPECT_EQ(readText(rgb), first_rgb);
}

/// A run that fails on its first frame replaces nothing (defect 3).
TEST_F(Reliability, FirstFrameFailureReplacesNothing)
{
  const std::string seq = copy();
  const std::string rgb = listed(seq, "rgb.txt", 0);
  fs::resize_file(rgb, fs::file_size(rgb) / 2);
  const std::string out = existing("t.txt"), objects = existing("o.txt");
  const auto result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out +
                                 " -objects " + objects);
  expectFailure(result, 1, rgb);
  EXPECT_NE(result.err.find("truncated PNG"), std::string::npos) << result.err;
  EXPECT_EQ(readText(out), KEEP);
  EXPECT_EQ(readText(objects), KEEP);
  EXPECT_FALSE(fs::exists(out + ".partial"));
  EXPECT_FALSE(fs::exists(objects + ".partial"));
  const auto segment = runCommand(SEGMENT + " -tum_dir " + seq + " -out_dir " +
                                  dir_.file("masks") + " -objects " + objects);
  expectFailure(segment, 1, rgb);
  EXPECT_EQ(readText(objects), KEEP);
  EXPECT_FALSE(fs::exists(objects + ".partial"));
}

/// Output paths are checked before the first frame, exit 2 (defect 4, and defect 8's
/// "-render_dir <a file>").
TEST_F(Reliability, OutputPathsAreCheckedUpFront)
{
  const std::string run = ODOMETRY + " -tum_dir " + sequence_->path();
  const std::string out = existing("t.txt");
  expectRefusedUpFront(runCommand(run + " -out " + dir_.file("missing/t.txt")),
                       "folder '" + dir_.file("missing") + "' does not exist");
  expectRefusedUpFront(runCommand(run + " -out " + dir_.path().string()),
                       "is a folder");
  expectRefusedUpFront(runCommand(run + " -out " + out + " -objects " + out),
                       out + ": is also given to -out");
  expectRefusedUpFront(runCommand(run + " -labels_dir " + out), out + ": is a file");
  expectRefusedUpFront(runCommand(run + " -render_dir " + out), out + ": is a file");
  EXPECT_EQ(readText(out), KEEP);
  EXPECT_FALSE(fs::exists(out + ".partial"));
  EXPECT_FALSE(fs::exists(dir_.file("missing")));

  // A file may go into an output folder the run creates.
  const auto inside = runCommand(run + " -labels_dir " + dir_.file("new") + " -out " +
                                 dir_.file("new/t.txt"));
  EXPECT_EQ(inside.exit_code, 0) << inside.err;
  EXPECT_EQ(dynvo::readTrajectory(dir_.file("new/t.txt")).size(),
            static_cast<std::size_t>(FRAMES));
}

/// A PCD file with the given header lines and data bytes, in its own folder.
std::string
writePcd(const TempDir& dir,
         const std::string& name,
         const std::string& count,
         const std::string& width,
         const std::string& height,
         const std::string& points,
         const std::string& data,
         const std::string& body)
{
  fs::create_directory(dir.file(name));
  const std::string file = dir.file(name) + "/0.pcd";
  writeText(file,
            "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F "
            "U\nCOUNT " +
                count + "\nWIDTH " + width + "\nHEIGHT " + height +
                "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + points + "\nDATA " + data +
                "\n" + body);
  return file;
}

/// Small files whose headers claim huge frames are refused before anything is allocated
/// (defect 5). Under a 1.5 GB address-space limit a 1.6 GB allocation would fail too, so
/// the message, not the limit, shows where the file was stopped.
TEST_F(Reliability, HugeHeadersAreRefusedBeforeAllocating)
{
  const std::string out = existing("t.txt");
  const std::string zeros(1000, '\0');
  const auto run = [&](const std::string& file, const std::string& flags = "") {
    return runCommand(ODOMETRY + " -pcd_dir " + fs::path(file).parent_path().string() +
                      " -out " + out + " " + flags);
  };
  const std::string wide =
      writePcd(dir_, "wide", "1 1 1 1", "10000", "10000", "100000000", "binary", zeros);
  auto result = run(wide);
  expectFailure(result, 1,
                wide + ": frame of 10000x10000 px is over the frame-size limit");
  // Raising the limit lets the header through to the next check: the file size.
  result = run(wide, "-max_frame_pixels 100000000");
  expectFailure(result, 1,
                wide + ": cannot read PCD file: the header's 100000000 points");
  EXPECT_NE(result.err.find("need more than the 1000 bytes"), std::string::npos);

  const std::string count = writePcd(dir_, "count", "1 1 1 500000000", "640", "480",
                                     "307200", "binary", zeros);
  expectFailure(run(count), 1, count + ": cannot read PCD file: the header's 307200");
  const std::string compressed =
      writePcd(dir_, "compressed", "1 1 1 1", "4000", "4000", "16000000",
               "binary_compressed", std::string("\x10\0\0\0\0\0\0\x10", 8) + zeros);
  expectFailure(run(compressed), 1, compressed + ": cannot read PCD file");
  EXPECT_EQ(readText(out), KEEP);

  // A PNG whose header claims 10000x10000 px (IHDR only; never decoded).
  const std::string seq = copy();
  const std::string rgb = listed(seq, "rgb.txt", 0);
  std::string png(
      "\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x27\x10\0\0\x27\x10\x08\x02\0\0\0"
      "\0\0\0\0",
      33);
  png += std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12);
  writeText(rgb, png);
  result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
  expectFailure(result, 1,
                rgb + ": frame of 10000x10000 px is over the frame-size limit");
  EXPECT_EQ(readText(out), KEEP);
  expectFailure(runCommand(ODOMETRY + " -tum_dir " + seq + " -max_frame_pixels 0"), 2,
                "-max_frame_pixels must be in [1,");
}

/// Stamps must be finite decimals; frames dropped by association are counted in one
/// warning; -seed out of range is a usage error (defect 7).
TEST_F(Reliability, BadStampsAndSeeds)
{
  const std::string out = existing("t.txt");
  for (const std::string stamp : {"0x1p3", "inf", "nan", "1.5s", "1e999"}) {
    const std::string seq = copy();
    std::string index = readText(seq + "/rgb.txt");
    const std::size_t line = index.find("\n1.0");
    index.replace(line + 1, index.find(' ', line) - line - 1, stamp);
    writeText(seq + "/rgb.txt", index);
    const auto result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
    expectFailure(result, 1, seq + "/rgb.txt:");
    EXPECT_NE(result.err.find(": bad timestamp '" + stamp + "'"), std::string::npos)
        << result.err;
    fs::remove_all(seq);
  }
  EXPECT_EQ(readText(out), KEEP);

  // Two colour images with the same stamp: one is dropped, and the run says so once.
  const std::string seq = copy();
  const std::string index = readText(seq + "/rgb.txt");
  const std::size_t third = index.find("\n1.06");
  std::istringstream lines(index.substr(index.find("\n1.03") + 1));
  std::string second;
  std::getline(lines, second);
  writeText(seq + "/rgb.txt", index.substr(0, third + 1) +
                                  second.substr(0, second.find(' ')) +
                                  index.substr(index.find(' ', third)));
  const auto duplicate =
      runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + dir_.file("d.txt"));
  EXPECT_EQ(duplicate.exit_code, 0) << duplicate.err;
  EXPECT_NE(duplicate.err.find(seq + ": 1 of 12 colour images have no depth image"),
            std::string::npos)
      << duplicate.err;
  EXPECT_EQ(dynvo::readTrajectory(dir_.file("d.txt")).size(), 11u);

  for (const std::string seed : {"4294967296", "-1"})
    expectRefusedUpFront(runCommand(ODOMETRY + " -tum_dir " + seq + " -seed " + seed),
                         "-seed must be in [0, 4294967295], got " + seed);
}

/// Messages name the file and the problem (defect 8).
TEST_F(Reliability, MessagesNameTheFileAndTheProblem)
{
  // A 1x1 recording.
  const std::string seq = copy();
  for (int k = 0; k < FRAMES; ++k) {
    cv::imwrite(listed(seq, "rgb.txt", k), cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)));
    cv::imwrite(listed(seq, "depth.txt", k), cv::Mat(1, 1, CV_16UC1, cv::Scalar(5000)));
  }
  // Every frame is reported and flagged lost; the run goes on and writes its trajectory.
  const std::string out = existing("t.txt");
  auto result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("got 1x1"), std::string::npos) << result.err;
  EXPECT_NE(result.out.find("lost=" + std::to_string(FRAMES)), std::string::npos)
      << result.out;
  EXPECT_EQ(dynvo::readTrajectory(out).size(), static_cast<std::size_t>(FRAMES));
  writeText(out, KEEP);

  // dynvo_evaluate on an empty, a one-line and a folder input, and on coordinates
  // whose squares overflow.
  dynvo::Trajectory poses(3);
  for (std::size_t k = 0; k < poses.size(); ++k)
    poses[k].timestamp = static_cast<double>(k);
  dynvo::writeTrajectory(dir_.file("gt.txt"), poses);
  writeText(dir_.file("empty.txt"), "");
  writeText(dir_.file("one.txt"), "1 0 0 0 0 0 0 1\n");
  writeText(dir_.file("huge.txt"), "0 1e200 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  const std::string gt = dir_.file("gt.txt");
  for (const auto& [file, problem] : std::vector<std::pair<std::string, std::string>>{
           {dir_.file("empty.txt"), ": holds 0 pose(s); at least 2 are needed"},
           {dir_.file("one.txt"), ": holds 1 pose(s); at least 2 are needed"},
           {dir_.file("labels"), ": is a folder, not a trajectory file"},
           {dir_.file("huge.txt"), ":1: value '1e200' is out of range"}}) {
    fs::create_directories(dir_.file("labels"));
    result = runCommand(EVALUATE + " " + gt + " " + file);
    expectFailure(result, 1, file + problem);
    EXPECT_EQ(result.out, "");
  }

  // A truncated PNG: dynvo's line comes first, libpng says nothing.
  const std::string rgb = listed(seq, "rgb.txt", 0);
  cv::imwrite(rgb, cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
  fs::resize_file(rgb, fs::file_size(rgb) - 20);
  result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
  expectFailure(result, 1, rgb + ": colour image is a truncated PNG");
  EXPECT_EQ(result.err.find("libpng"), std::string::npos) << result.err;

  // An empty file (a recording cut while it was written) is named as such.
  fs::resize_file(rgb, 0);
  result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
  expectFailure(result, 1, rgb + ": colour image is empty (0 bytes)");

  // A file name of 100,000 characters is cut in the message.
  const std::string name(100000, 'n');
  writeText(seq + "/rgb.txt", "1.0 " + name + ".png\n");
  writeText(seq + "/depth.txt", "1.0 " + name + ".png\n");
  result = runCommand(ODOMETRY + " -tum_dir " + seq + " -out " + out);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_LT(result.err.size(), 1000u) << result.err.size();
  EXPECT_NE(result.err.find("characters)...nnnn"), std::string::npos) << result.err;
  EXPECT_EQ(readText(out), KEEP);
}

} // namespace
