#pragma once
// The paths a command writes, checked before any work, so a typo costs nothing and a wrong folder is never
// destroyed. Every failure throws IoError(PATH, OPTION, why), printed as `[error] PATH (--out): why`.
//
// Output folders are staged: written as OUT.partial/ (with a marker file, so a later run knows the leftover is its
// own) and swapped in as OUT only when complete. An existing OUT is replaced only when the command's own test says
// it is an earlier output of that command, and never when it is `/`, the home folder, the working folder or one of
// its ancestors (`.`, `..`), a symbolic link or a file.
#include <filesystem>
#include <functional>
#include <string>

namespace drover::io {

// A file that OPTION will write (atomically: a temporary beside it, then renamed): not a folder, a device or a
// name ending in '/', in an existing folder that can be written. An empty path (the option not given) passes.
void checkOutputFile(const std::string& path, const std::string& option);

// A folder that OPTION will create (with missing parents) or write files into: not a file, and its nearest
// existing ancestor is a folder that can be written.
void checkOutputFolder(const std::string& path, const std::string& option);

// Why DIR (an existing folder) may never be deleted or replaced whatever it holds: "/", "the home folder", "the
// working folder" or "an ancestor of the working folder" (symbolic links resolved); "" when none of these.
std::string protectedFolderReason(const std::filesystem::path& dir);

// The marker file written first into OUT.partial/, and the folder an earlier OUT is parked in while it is replaced
// where the file system cannot swap two folders in one step. A command's "is this my output" test accepts both.
inline constexpr const char* kPartialMarker = ".drover-partial";
inline constexpr const char* kPreviousFolder = ".drover-previous";
// True for kPartialMarker, kPreviousFolder and the `NAME.tmp.PID` temporaries of writeFileAtomically.
bool isStagingLeftover(const std::string& file_name);

// "" when DIR (an existing folder) may be replaced, else why not (e.g. "holds notes.txt, which drover run does not
// write"); also asked about a leftover OUT.partial that has no marker.
using ReplaceTest = std::function<std::string(const std::filesystem::path& dir)>;

struct StagingRules {
  std::string option = "--out";
  bool may_replace = true;   // false: an existing OUT is an error, with replace_hint appended
  std::string replace_hint;  // e.g. "use --force to replace it"
  ReplaceTest replaceable;   // required
  std::string refusal;       // appended to replaceable's answer, e.g. "drover run replaces only an earlier run folder"
};

// A folder written as OUT.partial/ and renamed to OUT by publish().
class StagedFolder {
 public:
  // Checks OUT and OUT.partial as the constructor does, without touching anything. Returns OUT as an absolute
  // path without a trailing '/'.
  static std::filesystem::path check(const std::string& out, const StagingRules& rules);

  // Checks again, removes a leftover OUT.partial (one with the marker, or one the rules would replace), creates
  // OUT.partial/ and writes the marker into it.
  StagedFolder(const std::string& out, const StagingRules& rules);
  // Without publish(): removes OUT.partial/ (a failed command leaves nothing behind).
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  const std::filesystem::path& dir() const { return partial_; }  // write here
  const std::filesystem::path& out() const { return out_; }

  // Removes the marker and puts OUT.partial in OUT's place. An earlier OUT stays whole until the new one is
  // complete: the two are swapped in one step (Linux renameat2 RENAME_EXCHANGE), or where the file system cannot,
  // the old one is first parked inside the new one (kPreviousFolder) and removed once the new one is in place.
  void publish();

 private:
  std::filesystem::path out_, partial_;
  std::string option_;
  bool published_ = false;
};

// StagedFolder::publish's way where the file system cannot swap two folders: moves OUT to PARTIAL/kPreviousFolder,
// PARTIAL to OUT, then removes OUT/kPreviousFolder (killed in between, the earlier OUT is still inside PARTIAL or
// OUT). Public for its test.
void replaceByParking(const std::filesystem::path& partial, const std::filesystem::path& out,
                      const std::string& option);

}  // namespace drover::io
