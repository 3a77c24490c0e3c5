// The `odometry:` section of a platform config, its bad input: every mistake (an unknown key, a wrong type, a value
// that fails validation, a missing or broken file) is an IoError naming the file, the line and the dotted key. The
// keys' mapping onto their fields is in test_odometry_config.cpp.
#include <gtest/gtest.h>

#include <string>

#include "io/error.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "odometry_config_test_util.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using pipeline::OdometryConfig;

using test_config::errorOf;
using test_config::has;
using test_config::load;

TEST(OdometryConfigReader, UnknownTopLevelKeyNamesFileLineDottedKeyAndListsTheKnownKeys) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "dataset:\n  load_imu: true\nodometry:\n  use_imu: true\n  usee_imu: false\n");
  EXPECT_TRUE(has(e, (dir / "odometry.yaml").string())) << e;
  EXPECT_TRUE(has(e, "line 5")) << e;
  EXPECT_TRUE(has(e, "'odometry.usee_imu'")) << e;
  EXPECT_TRUE(has(e, "unknown key")) << e;
  // The known keys: plain ones and the nested sections.
  for (const char* k : {"use_imu", "deskew", "imu_wait", "layout", "matcher", "smoother"})
    EXPECT_TRUE(has(e, k)) << k << " missing from: " << e;
}

TEST(OdometryConfigReader, UnknownNestedKeyNamesFileLineDottedKeyAndListsThatSectionsKeysOnly) {
  test::TempDir dir;
  const std::string e =
      errorOf(dir, "odometry:\n  use_imu: false\n  matcher:\n    kernel: huber\n    max_iteratons: 5\n");
  EXPECT_TRUE(has(e, (dir / "odometry.yaml").string())) << e;
  EXPECT_TRUE(has(e, "line 5")) << e;
  EXPECT_TRUE(has(e, "'odometry.matcher.max_iteratons'")) << e;
  for (const char* k : {"max_iterations", "kernel", "huber_delta", "min_correspondences"})
    EXPECT_TRUE(has(e, k)) << k << " missing from: " << e;
  EXPECT_FALSE(has(e, "use_imu")) << "lists the top-level keys instead of the matcher's: " << e;
}

TEST(OdometryConfigReader, AStringForANumberIsAnErrorNamingLineAndKey) {
  test::TempDir dir;
  const std::string i = errorOf(dir, "odometry:\n  matcher:\n    max_iterations: many\n");
  EXPECT_TRUE(has(i, "line 3") && has(i, "'odometry.matcher.max_iterations'") && has(i, "many")) << i;
  const std::string d = errorOf(dir, "odometry:\n  imu_wait: soon\n");
  EXPECT_TRUE(has(d, "line 2") && has(d, "'odometry.imu_wait'") && has(d, "soon")) << d;
  const std::string unit = errorOf(dir, "odometry:\n  keyframes:\n    distance: 1.0m\n");
  EXPECT_TRUE(has(unit, "'odometry.keyframes.distance'")) << unit;
}

TEST(OdometryConfigReader, AFractionForAnIntegerAndAnOutOfRangeIntegerAreErrors) {
  test::TempDir dir;
  const std::string f = errorOf(dir, "odometry:\n  layout:\n    n_rings: 64.5\n");
  EXPECT_TRUE(has(f, "line 3") && has(f, "'odometry.layout.n_rings'")) << f;
  const std::string r = errorOf(dir, "odometry:\n  layout:\n    n_rings: 99999999999\n");
  EXPECT_TRUE(has(r, "'odometry.layout.n_rings'") && has(r, "out of range")) << r;
}

TEST(OdometryConfigReader, AKeyWrittenTwiceIsAnErrorNotTheLastValue) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  matcher:\n    max_iterations: 5\n    max_iterations: 30\n");
  EXPECT_TRUE(has(e, "line 4, key 'odometry.matcher.max_iterations'") && has(e, "duplicate key (first at line 3)"))
      << e;
}

TEST(OdometryConfigReader, ASectionWrittenTwiceIsAnErrorNotIgnored) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "loop:\n  enabled: true\nodometry:\n  use_imu: true\nloop:\n  enabled: false\n");
  EXPECT_TRUE(has(e, "line 5, section 'loop'") && has(e, "duplicate section (first at line 1)")) << e;
}

TEST(OdometryConfigReader, SecondsKeysMustConvertToNanosecondsWithoutOverflow) {
  test::TempDir dir;
  // 1e10 s overflowed int64 nanoseconds in the core's fromSeconds.
  const std::string e = errorOf(dir, "loop:\n  min_age: 1e10\n");
  EXPECT_TRUE(has(e, "line 2, key 'loop.min_age'") && has(e, "beyond the largest time")) << e;
  const std::string n = errorOf(dir, "odometry:\n  imu_wait: -1\n");
  EXPECT_TRUE(has(n, "'odometry.imu_wait'") && has(n, "expected [0, inf] s")) << n;
}

TEST(OdometryConfigReader, MaybeForABoolIsAnErrorAskingForTrueOrFalse) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  layout:\n    order_top_down: maybe\n");
  EXPECT_TRUE(has(e, "line 3") && has(e, "'odometry.layout.order_top_down'") && has(e, "true or false")) << e;
}

TEST(OdometryConfigReader, NonFiniteNumbersAreErrors) {
  test::TempDir dir;
  for (const char* v : {"nan", "inf", "-inf", ".inf", "1e400"}) {
    const std::string e = errorOf(dir, std::string("odometry:\n  imu_wait: ") + v + "\n");
    EXPECT_TRUE(has(e, "line 2") && has(e, "'odometry.imu_wait'")) << v << ": " << e;
  }
}

TEST(OdometryConfigReader, ASequenceOrMapWhereAValueBelongsIsAnError) {
  test::TempDir dir;
  const std::string s = errorOf(dir, "odometry:\n  layout:\n    n_rings: [16, 32]\n");
  EXPECT_TRUE(has(s, "line 3") && has(s, "'odometry.layout.n_rings'")) << s;
  const std::string m = errorOf(dir, "odometry:\n  deskew:\n    enabled: true\n");
  EXPECT_TRUE(has(m, "'odometry.deskew'")) << m;
}

TEST(OdometryConfigReader, ASectionThatIsNotAMapIsAnError) {
  test::TempDir dir;
  const std::string nested = errorOf(dir, "odometry:\n  layout: 5\n");
  EXPECT_TRUE(has(nested, "'odometry.layout'") && has(nested, "expected a map")) << nested;
  const std::string top = errorOf(dir, "odometry:\n  - use_imu\n");
  EXPECT_TRUE(has(top, "'odometry'") && has(top, "expected a map")) << top;
}

TEST(OdometryConfigReader, BadEnumerationValuesNameTheKeyAndListTheAllowedValues) {
  test::TempDir dir;
  const std::string file = (dir / "odometry.yaml").string();
  const std::string spin = errorOf(dir, "odometry:\n  layout:\n    spin: clockwise\n");
  EXPECT_TRUE(has(spin, file) && has(spin, "'odometry.layout.spin'") && has(spin, "ccw or cw") &&
              has(spin, "'clockwise'"))
      << spin;
  const std::string ring = errorOf(dir, "odometry:\n  layout:\n    ring_source: guess\n");
  EXPECT_TRUE(has(ring, "'odometry.layout.ring_source'") && has(ring, "elevation or order")) << ring;
  const std::string kernel = errorOf(dir, "odometry:\n  matcher:\n    kernel: Huber\n");  // case matters
  EXPECT_TRUE(has(kernel, "'odometry.matcher.kernel'") && has(kernel, "lio-sam or huber")) << kernel;
}

TEST(OdometryConfigReader, BadEnumerationValueNamesItsLine) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  use_imu: true\n  matcher:\n    kernel: cauchy\n");
  EXPECT_TRUE(has(e, "line 4") && has(e, "'odometry.matcher.kernel'")) << e;
}

TEST(OdometryConfigReader, AValueThatFailsValidationIsAnErrorNamingFileAndTheOdometrySection) {
  test::TempDir dir;
  const std::string file = (dir / "odometry.yaml").string();
  const std::string k = errorOf(dir, "odometry:\n  keyframes:\n    distance: -1\n");
  EXPECT_TRUE(has(k, file) && has(k, "section 'odometry'") && has(k, "keyframe distance")) << k;
  const std::string w = errorOf(dir, "odometry:\n  smoother:\n    window: 1\n");
  EXPECT_TRUE(has(w, file) && has(w, "section 'odometry'") && has(w, "window")) << w;
}

TEST(OdometryConfigReader, ANegativeMovingOrStaticStartSettingIsAnErrorNamingTheKey) {
  test::TempDir dir;
  const std::string r = errorOf(dir, "odometry:\n  moving_start_restart: -1\n");
  EXPECT_TRUE(has(r, "section 'odometry'") && has(r, "moving_start_restart must be >= 0")) << r;
  const std::string v = errorOf(dir, "odometry:\n  moving_start_speed: -0.5\n");
  EXPECT_TRUE(has(v, "section 'odometry'") && has(v, "moving_start_speed must be finite and >= 0")) << v;
  const std::string s = errorOf(dir, "odometry:\n  static_start_sigma_velocity: -0.01\n");
  EXPECT_TRUE(has(s, "section 'odometry'") && has(s, "static_start_sigma_velocity must be finite and >= 0")) << s;
}

TEST(OdometryConfigReader, TheStaticHoldKeysReachTheirFieldsAndANegativeSigmaIsAnErrorNamingTheKey) {
  test::TempDir dir;
  const OdometryConfig c =
      load(dir, "odometry:\n  static_hold:\n    sigma: 0.002\n    max_velocity: 0.03\n    max_rotation: 0.02\n");
  EXPECT_DOUBLE_EQ(c.static_hold.sigma, 0.002);
  EXPECT_DOUBLE_EQ(c.static_hold.max_velocity, 0.03);
  EXPECT_DOUBLE_EQ(c.static_hold.max_rotation, 0.02);
  EXPECT_EQ(OdometryConfig{}.static_hold.sigma, 0.0) << "off by default";
  const std::string e = errorOf(dir, "odometry:\n  static_hold:\n    sigma: -0.001\n");
  EXPECT_TRUE(has(e, "section 'odometry'") && has(e, "static_hold: sigma must be finite and >= 0")) << e;
}

TEST(OdometryConfigReader, APlaneAspectOutsideZeroToOneIsAnErrorNamingFileAndKey) {
  test::TempDir dir;
  const std::string file = (dir / "odometry.yaml").string();
  for (const char* value : {"1.0", "-0.1"}) {
    const std::string e = errorOf(dir, std::string("odometry:\n  matcher:\n    plane_min_aspect: ") + value + "\n");
    EXPECT_TRUE(has(e, file) && has(e, "section 'odometry'") && has(e, "plane_min_aspect must be in [0, 1)")) << e;
  }
}

TEST(OdometryConfigReader, AMissingFileIsAnErrorNamingIt) {
  test::TempDir dir;
  const std::string path = (dir / "absent.yaml").string();
  try {
    loadOdometryConfig(path);
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_TRUE(has(e.what(), "not found")) << e.what();
  }
}

TEST(OdometryConfigReader, InvalidYamlIsAnErrorNamingFileAndLine) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  use_imu: true\n  layout: [16\n");
  EXPECT_TRUE(has(e, (dir / "odometry.yaml").string()) && has(e, "invalid YAML") && has(e, "line ")) << e;
}

TEST(OdometryConfigReader, ANegativeUnaidedLidarRotationSigmaIsAnErrorNamingTheKey) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  lidar_sigma_rotation_unaided: -0.05\n");
  EXPECT_TRUE(has(e, "section 'odometry'") && has(e, "lidar_sigma_rotation_unaided must be finite and >= 0")) << e;
}

TEST(OdometryConfigReader, ANegativePerCorrespondenceDegeneracyThresholdIsAnErrorNamingTheKey) {
  test::TempDir dir;
  const std::string e = errorOf(dir, "odometry:\n  matcher:\n    degeneracy_threshold_per_correspondence: -0.02\n");
  EXPECT_TRUE(has(e, "degeneracy_threshold_per_correspondence must be finite and >= 0")) << e;
}

}  // namespace
}  // namespace drover::io
