// The one door of files read (skybake/base/file_door.h): what it refuses
// before reading a byte (directories, FIFOs, devices, links where none is
// expected, names that leave the folder), its caps, and that a kept read
// returns the bytes of its first read.
#include "skybake/base/file_door.h"

#include <filesystem>
#include <fstream>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

TEST(FileDoor, ARegularFileIsRead) {
  const std::string dir = testing::FreshTempDir("door_regular");
  testing::WriteFile(dir, "a.json", "[1, 2]");
  std::string bytes;
  EXPECT_EQ(ReadRegularFile(dir + "/a.json", 100, FileLinks::kRefuse, bytes), "");
  EXPECT_EQ(bytes, "[1, 2]");
  EXPECT_EQ(ReadFolderFile(dir, "a.json", 100, bytes), "");
  EXPECT_EQ(bytes, "[1, 2]");
  fs::remove_all(dir);
}

// A FIFO with no writer: a blocking open would wait for ever; the door
// opens it non-blocking and refuses it before reading.
TEST(FileDoor, FifoDirectoryAndDeviceAreRefusedUnread) {
  const std::string dir = testing::FreshTempDir("door_kinds");
  ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0600), 0);
  fs::create_directory(dir + "/sub");
  std::string bytes;
  EXPECT_EQ(ReadRegularFile(dir + "/fifo", 100, FileLinks::kFollow, bytes),
            "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(ReadRegularFile(dir + "/sub", 100, FileLinks::kFollow, bytes), "is a directory, not a file");
  EXPECT_EQ(ReadRegularFile("/dev/zero", 100, FileLinks::kFollow, bytes), "is a device, not a regular file");
  EXPECT_EQ(ReadRegularFile("/dev/null", 100, FileLinks::kFollow, bytes), "is a device, not a regular file");
  EXPECT_EQ(ReadFolderFile(dir, "fifo", 100, bytes), "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(ReadFolderFile(dir, "sub", 100, bytes), "is a directory, not a file");
  EXPECT_EQ(ReadRegularFile(dir + "/none", 100, FileLinks::kFollow, bytes), "no such file");
  fs::remove_all(dir);
}

// A link to /dev/zero is a device once followed; a link in a folder is not
// followed at all.
TEST(FileDoor, LinksAreFollowedOnlyWhereExpected) {
  const std::string dir = testing::FreshTempDir("door_links");
  testing::WriteFile(dir, "real.txt", "real");
  fs::create_symlink(dir + "/real.txt", dir + "/link.txt");
  fs::create_symlink("/dev/zero", dir + "/zero");
  fs::create_symlink("/etc/passwd", dir + "/passwd");
  std::string bytes;
  EXPECT_EQ(ReadRegularFile(dir + "/link.txt", 100, FileLinks::kFollow, bytes), "");
  EXPECT_EQ(bytes, "real");
  EXPECT_EQ(ReadRegularFile(dir + "/link.txt", 100, FileLinks::kRefuse, bytes),
            "is a symbolic link, which is not followed here");
  EXPECT_EQ(ReadRegularFile(dir + "/zero", 100, FileLinks::kFollow, bytes), "is a device, not a regular file");
  EXPECT_EQ(ReadFolderFile(dir, "passwd", 1 << 20, bytes), "is a symbolic link, which is not followed here");
  EXPECT_EQ(ReadFolderFile(dir, "zero", 100, bytes), "is a symbolic link, which is not followed here");
  fs::remove_all(dir);
}

// Names from a manifest: only a plain name of the folder opens.
TEST(FileDoor, NamesThatLeaveTheFolderAreRefused) {
  const std::string dir = testing::FreshTempDir("door_names");
  testing::WriteFile(dir, "in.txt", "in");
  fs::create_directory(dir + "/sub");
  testing::WriteFile(dir + "/sub", "deep.txt", "deep");
  std::string bytes;
  for (const char* name : {"../door_names/in.txt", "/etc/passwd", "sub/deep.txt", "..", ".", "", "a\\b"})
    EXPECT_NE(ReadFolderFile(dir, name, 100, bytes), "") << name;
  EXPECT_EQ(FolderNameProblem("/etc/passwd"), "is a path, not a plain file name of the folder");
  EXPECT_EQ(FolderNameProblem(".."), "names a folder, not a file in it");
  EXPECT_EQ(FolderNameProblem("sky\x1b[2J.exr"), "has a control character");
  EXPECT_EQ(FolderNameProblem(std::string(256, 'a')), "is longer than the 255 bytes of a file name");
  EXPECT_EQ(FolderNameProblem("sky_px.0001.exr"), "");
  fs::remove_all(dir);
}

// The cap holds whatever the size says: a regular file over it, and a
// /proc file (size 0) read only up to it.
TEST(FileDoor, SizeIsCapped) {
  const std::string dir = testing::FreshTempDir("door_cap");
  testing::WriteFile(dir, "big.txt", std::string(1000, 'x'));
  std::string bytes;
  EXPECT_EQ(ReadRegularFile(dir + "/big.txt", 999, FileLinks::kFollow, bytes),
            "is 1000 bytes, more than the 0 MiB such a file may have");
  EXPECT_TRUE(bytes.empty());
  EXPECT_EQ(ReadRegularFile(dir + "/big.txt", 1000, FileLinks::kFollow, bytes), "");
  EXPECT_EQ(ReadRegularFile("/proc/self/maps", 10, FileLinks::kFollow, bytes),
            "is more than the 0 MiB such a file may have");
  fs::remove_all(dir);
}

// Read once (no scope open: once per process, as the CLI reads): a file
// changed (or removed) after its first read gives the first bytes again; a
// problem is kept too.
TEST(FileDoor, AKeptReadIsTheFirstRead) {
  const std::string dir = testing::FreshTempDir("door_kept");
  const std::string path = testing::WriteFile(dir, "catalogue.json", "first");
  std::shared_ptr<const std::string> bytes;
  ASSERT_EQ(ReadKept(path, 100, bytes), "");
  EXPECT_EQ(*bytes, "first");
  testing::WriteFile(dir, "catalogue.json", "second, longer");
  std::shared_ptr<const std::string> again;
  ASSERT_EQ(ReadKept(path, 100, again), "");
  EXPECT_EQ(*again, "first");
  fs::remove(path);
  ASSERT_EQ(ReadKept(path, 100, again), "");
  EXPECT_EQ(*again, "first");
  EXPECT_EQ(ReadKept(dir + "/absent.json", 100, again), "no such file");
  testing::WriteFile(dir, "absent.json", "late");
  EXPECT_EQ(ReadKept(dir + "/absent.json", 100, again), "no such file");
  fs::remove_all(dir);
}

// Scopes (one per Python call): within overlapping scopes a kept read stays
// the first; the first scope opened after all closed reads the file anew,
// problem or bytes; bytes handed out before stay valid.
TEST(FileDoor, AKeptReadScopeStartsAfreshWhenNoneIsOpen) {
  const std::string dir = testing::FreshTempDir("door_kept_scope");
  const std::string path = testing::WriteFile(dir, "config.ocio", "first");
  std::shared_ptr<const std::string> bytes, again;
  {
    const KeptReadScope bake;
    ASSERT_EQ(ReadKept(path, 100, bytes), "");
    EXPECT_EQ(*bytes, "first");
    testing::WriteFile(dir, "config.ocio", "second");
    {
      const KeptReadScope other_thread;  // overlapping: shares the reads
      ASSERT_EQ(ReadKept(path, 100, again), "");
      EXPECT_EQ(*again, "first");
    }
    ASSERT_EQ(ReadKept(path, 100, again), "");
    EXPECT_EQ(*again, "first");
  }
  {
    const KeptReadScope next_bake;
    ASSERT_EQ(ReadKept(path, 100, again), "");
    EXPECT_EQ(*again, "second");
    EXPECT_EQ(*bytes, "first");
    fs::remove(path);
  }
  const KeptReadScope removed;
  EXPECT_EQ(ReadKept(path, 100, again), "no such file");
  fs::remove_all(dir);
}

// An image a key names: a FIFO or a device is refused unread; an 8000 x
// 8000 PNG of zeros (a small file) is refused from its header, before its
// pixels (64 Mi samples as floats, 256 MiB) are decoded; a small image reads.
TEST(FileDoor, ImagesAreCheckedFromTheirHeaderBeforeDecoding) {
  const std::string dir = testing::FreshTempDir("door_images");
  ASSERT_EQ(::mkfifo((dir + "/fifo.png").c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir + "/zero.png");
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  EXPECT_EQ(ReadImageFile(dir + "/fifo.png", width, height, channels, pixels),
            "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(ReadImageFile(dir + "/zero.png", width, height, channels, pixels), "is a device, not a regular file");
  auto write_png = [&](const std::string& name, int w, int h, int c) {
    const std::vector<uint8_t> zeros(size_t(w) * h * c, 0);
    auto out = OIIO::ImageOutput::create(dir + "/" + name);
    ASSERT_TRUE(out && out->open(dir + "/" + name, OIIO::ImageSpec(w, h, c, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, zeros.data()));
    out->close();
  };
  write_png("huge.png", 8000, 8000, 4);
  EXPECT_LT(fs::file_size(dir + "/huge.png"), uint64_t(4) << 20) << "a small file";
  EXPECT_EQ(ReadImageFile(dir + "/huge.png", width, height, channels, pixels),
            "cannot read it as an image (8000 x 8000 texels of 4 channels, more than the 67108864 samples an input "
            "image may have (4096 x 4096 x 4))");
  EXPECT_TRUE(pixels.empty()) << "nothing decoded";
  write_png("small.png", 8, 4, 3);
  EXPECT_EQ(ReadImageFile(dir + "/small.png", width, height, channels, pixels), "");
  EXPECT_EQ(width * height * channels, 96);
  EXPECT_EQ(pixels.size(), 96u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
