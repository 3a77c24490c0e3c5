// `drover sim --force` replaces only an earlier simulated dataset (or an empty folder) and a leftover OUT.partial
// only when an interrupted sim left it; never `.`, `..`, the home folder, an ancestor of the working folder, a
// file, a link or a folder holding anything else. A refusal is one `[error] PATH (--out): why` line, exit code 2,
// before any simulation, and deletes nothing.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "support/cli.hpp"
#include "support/cli_process.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const std::string kSim = "sim --scenario straight --duration 0.5 --no-camera ";

std::set<std::string> namesIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir)) names.insert(fs::relative(e.path(), dir).string());
  return names;
}

// One `[error] OUT (--out): ...` line naming WHY, exit code 2, no simulation started.
void expectSimRefused(const CliResult& r, const std::string& out, const std::string& why) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("[error] " + out + " (--out): ", 0), 0u) << r.output;
  EXPECT_TRUE(contains(r.output, why)) << why << " missing from: " << r.output;
  EXPECT_FALSE(contains(r.output, "simulating")) << r.output;
}

fs::path makeDataset(const fs::path& out, const std::string& extra = "") {
  const CliResult r = runDrover(kSim + "-q --out " + out.string() + " " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out;
}

TEST(SimForceCli, RefusesTheWorkingFolderAndDeletesNothing) {
  TempDir dir;
  writeText(dir / "keep.txt", "mine");
  expectSimRefused(runDroverIn(dir.path(), kSim + "--force --out ."), ".", "is the working folder");
  expectSimRefused(runDroverIn(dir.path(), kSim + "--force --out ./"), "./", "is the working folder");
  EXPECT_EQ(namesIn(dir.path()), std::set<std::string>{"keep.txt"});
}

TEST(SimForceCli, RefusesTheParentAndAnyAncestorOfTheWorkingFolderWithOrWithoutATrailingSlash) {
  TempDir dir;
  writeText(dir / "a" / "keep.txt", "mine");
  fs::create_directories(dir / "a" / "b" / "c");
  const fs::path cwd = dir / "a" / "b" / "c";
  expectSimRefused(runDroverIn(cwd, kSim + "--force --out .."), "..", "is an ancestor of the working folder");
  expectSimRefused(runDroverIn(cwd, kSim + "--force --out ../../"), "../../", "is an ancestor of the working folder");
  const std::string a = (dir / "a").string() + "/";
  expectSimRefused(runDroverIn(cwd, kSim + "--force --out " + a), a, "is an ancestor of the working folder");
  EXPECT_EQ(namesIn(dir / "a"), (std::set<std::string>{"keep.txt", "b", "b/c"}));
}

TEST(SimForceCli, RefusesTheHomeFolderEvenWhenItHoldsADataset) {
  TempDir dir;
  const fs::path home = makeDataset(dir / "home");
  const std::set<std::string> before = namesIn(home);
  expectSimRefused(runDroverIn(dir.path(), kSim + "--force --out " + home.string(), "HOME=" + home.string()),
                home.string(), "is the home folder");
  EXPECT_EQ(namesIn(home), before);
}

TEST(SimForceCli, RefusesAFolderThatIsNotADatasetAndADatasetWithAUserFileAdded) {
  TempDir dir;
  writeText(dir / "mine" / "notes.txt", "mine");
  const std::string mine = (dir / "mine").string();
  expectSimRefused(runDrover(kSim + "--force --out " + mine), mine, "is not a complete simulated dataset");
  EXPECT_EQ(namesIn(dir / "mine"), std::set<std::string>{"notes.txt"});

  const fs::path ds = makeDataset(dir / "ds");
  writeText(ds / "lidar" / "labels.txt", "mine");
  const std::set<std::string> before = namesIn(ds);
  expectSimRefused(runDrover(kSim + "--force --out " + ds.string()), ds.string(),
                "holds lidar/labels.txt, which drover sim does not write");
  EXPECT_EQ(namesIn(ds), before);
}

TEST(SimForceCli, RefusesAPlainFileAndALinkToADataset) {
  TempDir dir;
  writeText(dir / "file.txt", "mine");
  const std::string file = (dir / "file.txt").string();
  expectSimRefused(runDrover(kSim + "--force --out " + file), file, "is a file, not a folder");
  EXPECT_EQ(readText(dir / "file.txt"), "mine");

  const fs::path ds = makeDataset(dir / "ds");
  fs::create_directory_symlink(ds, dir / "link");
  const std::string link = (dir / "link").string();
  expectSimRefused(runDrover(kSim + "--force --out " + link), link, "is a symbolic link");
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
  EXPECT_TRUE(fs::exists(ds / "calibration.yaml"));
}

TEST(SimForceCli, ReplacesAnEarlierDatasetAndAnEmptyFolder) {
  TempDir dir;
  const fs::path ds = makeDataset(dir / "ds", "--seed 1");
  const CliResult r = runDrover(kSim + "-q --force --seed 2 --out " + ds.string() + "/");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(readJson(ds / "scenario.json")["seed"], 2);
  EXPECT_EQ(namesIn(dir.path()).count("ds.partial"), 0u);
  fs::create_directories(dir / "empty");
  EXPECT_EQ(runDrover(kSim + "-q --force --out " + (dir / "empty").string()).exit_code, 0);
  EXPECT_TRUE(fs::exists(dir / "empty" / "calibration.yaml"));
}

TEST(SimForceCli, RemovesALeftoverPartialThatAnInterruptedSimMarkedButNotAForeignOne) {
  TempDir dir;
  writeText(dir / "ds.partial" / ".drover-partial", "");
  writeText(dir / "ds.partial" / "lidar" / "000000.bin", "half");
  const CliResult r = runDrover(kSim + "-q --out " + (dir / "ds").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "ds.partial"));

  writeText(dir / "other.partial" / "notes.txt", "mine");
  const CliResult foreign = runDrover(kSim + "--out " + (dir / "other").string());
  EXPECT_EQ(foreign.exit_code, 2) << foreign.output;
  EXPECT_EQ(foreign.output.rfind("[error] " + (dir / "other.partial").string() + " (--out): is in the way", 0), 0u)
      << foreign.output;
  EXPECT_EQ(readText(dir / "other.partial" / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(dir / "other"));
}

}  // namespace
}  // namespace drover::test
