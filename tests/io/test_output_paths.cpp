// io/output_paths: output files and folders are checked before any work, and a staged folder replaces only what its
// rules recognise, never `/`, the home folder, the working folder or its ancestors, and never loses the earlier
// folder before the new one is complete.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "io/error.hpp"
#include "io/output_paths.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;
using test::TempDir;
using test::writeText;

// The message of the IoError FN throws ("" when it throws none).
template <typename Fn>
std::string ioErrorOf(Fn&& fn) {
  try {
    fn();
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

// Changes the working folder for one test.
class WorkingFolder {
 public:
  explicit WorkingFolder(const fs::path& p) : old_(fs::current_path()) { fs::current_path(p); }
  ~WorkingFolder() { fs::current_path(old_); }

 private:
  fs::path old_;
};

std::set<std::string> namesIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// Rules that replace a folder holding only `result.txt` files (or nothing).
StagingRules resultRules() {
  StagingRules rules;
  rules.replaceable = [](const fs::path& dir) -> std::string {
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (name != "result.txt" && !isStagingLeftover(name)) return "holds " + name;
    }
    return "";
  };
  rules.refusal = "only results are replaced";
  return rules;
}

TEST(CheckOutputFile, AcceptsANewOrExistingFileInAWritableFolderAndNoPath) {
  TempDir dir;
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile((dir / "new.json").string(), "--json"); }), "");
  writeText(dir / "old.json", "{}");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile((dir / "old.json").string(), "--json"); }), "");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile("", "--json"); }), "");
}

TEST(CheckOutputFile, RefusesAFolderAMissingFolderAFileAsFolderATrailingSlashAndADevice) {
  TempDir dir;
  writeText(dir / "file", "x");
  const std::string folder = dir.path().string(), missing = (dir / "no" / "o.json").string(),
                    under_file = (dir / "file" / "o.json").string(), slash = (dir / "o.json/").string();
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile(folder, "--json"); }), folder + " (--json): is a folder, not a file");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile(missing, "--plot"); }),
            missing + " (--plot): folder " + (dir / "no").string() + " does not exist");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile(under_file, "--json"); }),
            under_file + " (--json): " + (dir / "file").string() + " is not a folder");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile(slash, "--json"); }), slash + " (--json): names a folder, not a file");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFile("/dev/null", "--json"); }), "/dev/null (--json): is not a regular file");
}

TEST(CheckOutputFolder, AcceptsNewNestedFoldersAndRefusesAFileOrAFileOnTheWay) {
  TempDir dir;
  writeText(dir / "file", "x");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFolder((dir / "a" / "b").string(), "--out"); }), "");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFolder(dir.path().string(), "--out"); }), "");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFolder((dir / "file").string(), "--out"); }),
            (dir / "file").string() + " (--out): is a file, not a folder");
  EXPECT_EQ(ioErrorOf([&] { checkOutputFolder((dir / "file" / "sub").string(), "--out"); }),
            (dir / "file" / "sub").string() + " (--out): " + (dir / "file").string() + " is not a folder");
}

TEST(ProtectedFolderReason, NamesTheRootHomeWorkingFolderAndItsAncestorsThroughLinks) {
  TempDir dir;
  fs::create_directories(dir / "a" / "b" / "c");
  fs::create_directory_symlink(dir / "a", dir / "link_to_a");
  const WorkingFolder cwd(dir / "a" / "b");
  EXPECT_EQ(protectedFolderReason("/"), "the root folder");
  EXPECT_EQ(protectedFolderReason("."), "the working folder");
  EXPECT_EQ(protectedFolderReason(".."), "an ancestor of the working folder");
  EXPECT_EQ(protectedFolderReason(dir / "link_to_a"), "an ancestor of the working folder");
  EXPECT_EQ(protectedFolderReason(dir.path()), "an ancestor of the working folder");
  EXPECT_EQ(protectedFolderReason("c"), "");
  const char* home = std::getenv("HOME");
  if (home && fs::is_directory(home)) {
    EXPECT_EQ(protectedFolderReason(home), "the home folder");
  }
}

TEST(IsStagingLeftover, KnowsTheMarkerTheParkedFolderAndAtomicWriteTemporaries) {
  EXPECT_TRUE(isStagingLeftover(".drover-partial"));
  EXPECT_TRUE(isStagingLeftover(".drover-previous"));
  EXPECT_TRUE(isStagingLeftover("report.json.tmp.1234"));
  EXPECT_FALSE(isStagingLeftover("report.json.tmp."));
  EXPECT_FALSE(isStagingLeftover("notes.tmp.txt"));
  EXPECT_FALSE(isStagingLeftover("notes.txt"));
}

TEST(StagedFolder, WritesIntoAMarkedPartialFolderAndRenamesItWhenPublished) {
  TempDir dir;
  const fs::path out = dir / "run";
  StagedFolder staged(out.string() + "/", resultRules());  // a trailing '/' names the same folder
  EXPECT_EQ(staged.out(), out);
  EXPECT_EQ(staged.dir(), dir / "run.partial");
  EXPECT_TRUE(fs::exists(staged.dir() / kPartialMarker));
  EXPECT_FALSE(fs::exists(out));
  writeText(staged.dir() / "result.txt", "new");
  staged.publish();
  EXPECT_EQ(namesIn(out), std::set<std::string>{"result.txt"}) << "the marker does not survive";
  EXPECT_FALSE(fs::exists(dir / "run.partial"));
}

TEST(StagedFolder, ReplacesAnEarlierFolderOnlyWhenPublishedKeepingItWholeUntilThen) {
  TempDir dir;
  const fs::path out = dir / "run";
  writeText(out / "result.txt", "old");
  {
    StagedFolder staged(out.string(), resultRules());
    writeText(staged.dir() / "result.txt", "new");
    EXPECT_EQ(namesIn(out), std::set<std::string>{"result.txt"});
    std::ifstream old(out / "result.txt");
    std::string text;
    old >> text;
    EXPECT_EQ(text, "old");
    staged.publish();
  }
  std::ifstream now(out / "result.txt");
  std::string text;
  now >> text;
  EXPECT_EQ(text, "new");
  EXPECT_EQ(namesIn(dir.path()), std::set<std::string>{"run"});
}

TEST(ReplaceByParking, PutsTheNewFolderInPlaceAndRemovesTheEarlierOne) {
  TempDir dir;
  writeText(dir / "run" / "result.txt", "old");
  writeText(dir / "run.partial" / "result.txt", "new");
  writeText(dir / "run.partial" / "extra.txt", "new");
  replaceByParking(dir / "run.partial", dir / "run", "--out");
  EXPECT_EQ(namesIn(dir.path()), std::set<std::string>{"run"});
  EXPECT_EQ(namesIn(dir / "run"), (std::set<std::string>{"result.txt", "extra.txt"}));
  std::ifstream now(dir / "run" / "result.txt");
  std::string text;
  now >> text;
  EXPECT_EQ(text, "new");
}

TEST(StagedFolder, ADestroyedUnpublishedFolderLeavesNothingAndTheEarlierFolderAsItWas) {
  TempDir dir;
  writeText(dir / "run" / "result.txt", "old");
  {
    StagedFolder staged((dir / "run").string(), resultRules());
    writeText(staged.dir() / "result.txt", "half");
  }
  EXPECT_EQ(namesIn(dir.path()), std::set<std::string>{"run"});
  EXPECT_EQ(namesIn(dir / "run"), std::set<std::string>{"result.txt"});
}

TEST(StagedFolder, RefusesAForeignFolderAFileALinkAndAnExistingFolderWhenReplacingIsOff) {
  TempDir dir;
  writeText(dir / "mine" / "notes.txt", "keep");
  writeText(dir / "file", "keep");
  fs::create_directories(dir / "results");
  fs::create_directory_symlink(dir / "results", dir / "link");
  const std::string mine = (dir / "mine").string(), file = (dir / "file").string(), link = (dir / "link").string();
  EXPECT_EQ(ioErrorOf([&] { StagedFolder(mine, resultRules()); }),
            mine + " (--out): holds notes.txt; only results are replaced");
  EXPECT_EQ(ioErrorOf([&] { StagedFolder(file, resultRules()); }), file + " (--out): is a file, not a folder");
  EXPECT_EQ(ioErrorOf([&] { StagedFolder(link, resultRules()); }),
            link + " (--out): is a symbolic link: give the folder it points to");
  StagingRules no_replace = resultRules();
  no_replace.may_replace = false;
  no_replace.replace_hint = "use --force to replace it";
  const std::string results = (dir / "results").string();
  EXPECT_EQ(ioErrorOf([&] { StagedFolder(results, no_replace); }),
            results + " (--out): already exists (use --force to replace it)");
  EXPECT_TRUE(fs::exists(dir / "mine" / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "file"));
  EXPECT_FALSE(fs::exists(dir / "mine.partial"));
}

TEST(StagedFolder, NeverReplacesTheWorkingFolderOrAnAncestorEvenWhenItsRulesWould) {
  TempDir dir;
  fs::create_directories(dir / "a" / "b");
  const WorkingFolder cwd(dir / "a" / "b");
  StagingRules anything = resultRules();
  anything.replaceable = [](const fs::path&) { return std::string(); };
  for (const std::string& out : std::vector<std::string>{".", "./", "..", "../", (dir / "a").string() + "/", "/"}) {
    SCOPED_TRACE(out);
    const std::string e = ioErrorOf([&] { StagedFolder(out, anything); });
    EXPECT_NE(e.find(out + " (--out): is "), std::string::npos) << e;
    EXPECT_NE(e.find("never replaced"), std::string::npos) << e;
  }
  EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
  EXPECT_EQ(namesIn(dir / "a"), std::set<std::string>{"b"});
}

TEST(StagedFolder, RemovesALeftoverPartialItMarkedOrTheRulesAcceptButNotAForeignOne) {
  TempDir dir;
  writeText(dir / "run.partial" / kPartialMarker, "");
  writeText(dir / "run.partial" / "notes.txt", "half-written");
  { StagedFolder staged((dir / "run").string(), resultRules()); }  // removed the marked leftover
  EXPECT_FALSE(fs::exists(dir / "run.partial"));

  writeText(dir / "run.partial" / "result.txt", "complete, its marker already removed");
  { StagedFolder staged((dir / "run").string(), resultRules()); }
  EXPECT_FALSE(fs::exists(dir / "run.partial"));

  writeText(dir / "run.partial" / "notes.txt", "the user's");
  const std::string e = ioErrorOf([&] { StagedFolder((dir / "run").string(), resultRules()); });
  EXPECT_EQ(e, (dir / "run.partial").string() +
                   " (--out): is in the way and not what an interrupted drover leaves (it holds notes.txt): remove it "
                   "or choose another --out");
  EXPECT_TRUE(fs::exists(dir / "run.partial" / "notes.txt"));
}

}  // namespace
}  // namespace drover::io
