#include "lidar/cloud_io.h"

#include "tests/testing/scoped_temp_dir.h"

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

class CloudIoTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.File(name); }

  static PointCloud RandomCloud(size_t n, bool attributes) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-20, 20);
    PointCloud cloud;
    for (size_t i = 0; i < n; ++i) {
      cloud.points.emplace_back(u(rng), u(rng), u(rng));
      if (attributes) {
        cloud.normals.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
        cloud.colors.emplace_back(i % 256, (3 * i) % 256, 255 - i % 256);
        cloud.intensities.push_back(static_cast<float>(i % 100));
      }
    }
    return cloud;
  }

  // Expects ReadPointCloud(path) to throw an error that names the file and contains `problem`.
  void ExpectReadError(const std::string& path, const std::string& problem) {
    try {
      ReadPointCloud(path);
      ADD_FAILURE() << "reading " << path << " succeeded";
    } catch (const std::runtime_error& error) {
      const std::string what = error.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
    }
  }

  testing::ScopedTempDir dir_;
};

TEST_F(CloudIoTest, PcdAndPlyRoundTripWithAllAttributes) {
  const PointCloud cloud = RandomCloud(1000, true);
  for (const char* name : {"a.pcd", "a.ply"}) {
    WritePointCloud(Path(name), cloud);
    CloudReadStats stats;
    const PointCloud read = ReadPointCloud(Path(name), &stats);
    ASSERT_EQ(read.Size(), cloud.Size()) << name;
    ASSERT_TRUE(read.HasNormals() && read.HasColors() && read.HasIntensities()) << name;
    EXPECT_EQ(stats.num_read, 1000u);
    EXPECT_EQ(stats.num_dropped_non_finite, 0u);
    double max_error = 0;
    for (size_t i = 0; i < cloud.Size(); ++i) {
      max_error = std::max(max_error, (read.points[i] - cloud.points[i]).norm());
      EXPECT_EQ(read.colors[i], cloud.colors[i]);
      EXPECT_FLOAT_EQ(read.intensities[i], cloud.intensities[i]);
      EXPECT_NEAR((read.normals[i] - cloud.normals[i]).norm(), 0, 1e-6);
    }
    // float32 storage: relative precision ~6e-8 at |x| <= 35 m.
    EXPECT_LT(max_error, 5e-6) << name;
    EXPECT_FALSE(fs::exists(Path(name) + ".tmp")) << "temporary file left";
  }
}

TEST_F(CloudIoTest, ReadsEveryPcdEncodingWrittenByPcl) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  for (int i = 0; i < 300; ++i) {
    pcl::PointXYZI p;
    p.x = 0.1f * i, p.y = -0.2f * i, p.z = 3.0f, p.intensity = static_cast<float>(i % 7);
    cloud.push_back(p);
  }
  cloud[5].x = std::nanf("");  // one NaN point inside a good file: dropped and counted
  ASSERT_EQ(pcl::io::savePCDFileASCII(Path("ascii.pcd"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinary(Path("binary.pcd"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(Path("compressed.pcd"), cloud), 0);
  for (const char* name : {"ascii.pcd", "binary.pcd", "compressed.pcd"}) {
    CloudReadStats stats;
    const PointCloud read = ReadPointCloud(Path(name), &stats);
    ASSERT_EQ(read.Size(), 299u) << name;
    EXPECT_EQ(stats.num_dropped_non_finite, 1u) << name;
    EXPECT_NEAR(read.points[10].x(), 1.1, 1e-5) << name;  // index 10 is point 11 after the NaN
    EXPECT_FLOAT_EQ(read.intensities[10], 11 % 7) << name;
  }
}

// A driver's per-point time field ("t", "time" or "timestamp") is read as it is; a NaN time is an
// error naming the file, not a point silently timed.
TEST_F(CloudIoTest, ReadsPerPointTimesOfPcdAndPly) {
  std::ofstream(Path("t.pcd")) << "VERSION 0.7\nFIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\n"
                                  "COUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                                  "POINTS 3\nDATA ascii\n1 0 0 0\n0 1 0 50000000\n0 0 1 99999999\n";
  const PointCloud pcd = ReadPointCloud(Path("t.pcd"));
  ASSERT_TRUE(pcd.HasTimes());
  EXPECT_EQ(pcd.times, std::vector<double>({0, 50000000, 99999999}));
  std::ofstream(Path("t.ply")) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                  "property float y\nproperty float z\nproperty double time\n"
                                  "end_header\n1 2 3 1317384000.25\n4 5 6 1317384000.30\n";
  const PointCloud ply = ReadPointCloud(Path("t.ply"));
  EXPECT_EQ(ply.times, std::vector<double>({1317384000.25, 1317384000.30}));
  std::ofstream(Path("nan.ply")) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                    "property float y\nproperty float z\nproperty double time\n"
                                    "end_header\n1 2 3 0.25\n4 5 6 nan\n";
  ExpectReadError(Path("nan.ply"), "NaN or infinite time");
}

TEST_F(CloudIoTest, ReadsKittiBinAndXyzText) {
  const std::vector<float> kitti = {1, 2, 3, 0.5f, 4, 5, 6, 0.25f};
  std::ofstream(Path("k.bin"), std::ios::binary)
      .write(reinterpret_cast<const char*>(kitti.data()), 32);
  const PointCloud k = ReadPointCloud(Path("k.bin"));
  ASSERT_EQ(k.Size(), 2u);
  EXPECT_EQ(k.points[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_FLOAT_EQ(k.intensities[0], 0.5f);

  std::ofstream(Path("p.xyz")) << "# comment\n1 2 3\n4.5 5 6\n\n7,8,9\n";
  const PointCloud t = ReadPointCloud(Path("p.xyz"));
  ASSERT_EQ(t.Size(), 3u);
  EXPECT_EQ(t.points[2], Eigen::Vector3d(7, 8, 9));
}

TEST_F(CloudIoTest, ReadsAsciiPlyAndDropsNonFinitePoints) {
  std::ofstream(Path("a.ply")) << "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\n"
                                  "property double y\nproperty double z\nelement face 0\n"
                                  "property list uchar int vertex_indices\nend_header\n"
                                  "0 0 0\n1 nan 1\n2 2 2\ninf 0 0\n";
  CloudReadStats stats;
  const PointCloud cloud = ReadPointCloud(Path("a.ply"), &stats);
  EXPECT_EQ(cloud.Size(), 2u);
  EXPECT_EQ(stats.num_read, 4u);
  EXPECT_EQ(stats.num_dropped_non_finite, 2u);
}

TEST_F(CloudIoTest, RejectsBadFilesWithTheFileNamed) {
  ExpectReadError(Path("missing.pcd"), "no such file");
  std::ofstream(Path("empty.ply"));
  ExpectReadError(Path("empty.ply"), "empty");

  // Truncated binary PLY and PCD: cut the last 100 bytes.
  const PointCloud cloud = RandomCloud(500, true);
  for (const char* name : {"cut.ply", "cut.pcd"}) {
    WritePointCloud(Path(name), cloud);
    fs::resize_file(Path(name), fs::file_size(Path(name)) - 100);
    ExpectReadError(Path(name), "truncated");
  }

  std::ofstream(Path("cut.bin"), std::ios::binary) << "0123456789";
  ExpectReadError(Path("cut.bin"), "multiple of 16");

  PointCloud nan_cloud;
  nan_cloud.points.assign(10, Eigen::Vector3d::Constant(std::nan("")));
  WritePointCloud(Path("nan.pcd"), nan_cloud);
  ExpectReadError(Path("nan.pcd"), "NaN");

  std::ofstream(Path("typed.ply")) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                      "property float y\nproperty float z\nend_header\n1 two 3\n";
  ExpectReadError(Path("typed.ply"), "not a number");

  std::ofstream(Path("noxyz.ply")) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\n"
                                      "end_header\n1\n";
  ExpectReadError(Path("noxyz.ply"), "x, y, z");

  std::ofstream(Path("notes.las")) << "x";
  ExpectReadError(Path("notes.las"), "unknown extension");
}

// A user's 1,000 random bytes named .pcd once made PCL's reader dereference null (SIGSEGV); a header
// claiming 10^12 points must be refused before anything is allocated.
TEST_F(CloudIoTest, RefusesPcdHeadersPclWouldTrust) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    std::string bytes(1000, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    std::ofstream(Path("random.pcd"), std::ios::binary) << bytes;
    ExpectReadError(Path("random.pcd"), "PCD");
  }
  const std::string fields = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(Path(name), std::ios::binary) << text;
    return Path(name);
  };
  const std::string huge = "WIDTH 1000000000000\nHEIGHT 1\nPOINTS 1000000000000\n";
  ExpectReadError(write("huge.pcd", fields + huge + "DATA binary\n" + std::string(24, 'a')),
                  "truncated");
  ExpectReadError(write("huge_ascii.pcd", fields + huge + "DATA ascii\n1 2 3\n"), "truncated");
  std::string sizes(8, '\0');
  const uint32_t stored[2] = {4, 4000000};
  std::memcpy(sizes.data(), stored, 8);
  ExpectReadError(
      write("huge_lzf.pcd",
            fields + "WIDTH 1000000\nHEIGHT 1\nPOINTS 1000000\nDATA binary_compressed\n" + sizes +
                "abcd"),
      "stored sizes");
  ExpectReadError(
      write("lengths.pcd",
            "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n"),
      "3 FIELDS but 2 SIZE");
  ExpectReadError(
      write("points.pcd", fields + "WIDTH 2\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n1 2 3\n"),
      "POINTS 3");
  ExpectReadError(
      write("type.pcd",
            "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n"),
      "field 'z'");
  ExpectReadError(write("nodata.pcd", fields + "WIDTH 1\n"), "no DATA line");
  ExpectReadError(write("nopoints.pcd", fields + "WIDTH 1\nDATA ascii\n1 2 3\n"), "no POINTS");
  // A good ascii header still reads through PCL.
  const std::string good =
      write("good.pcd", fields + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n");
  EXPECT_EQ(ReadPointCloud(good).Size(), 2u);
}

}  // namespace
}  // namespace colmap_lidar
