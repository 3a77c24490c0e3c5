#include "io/output_paths.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "io/error.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

// "out/", "out/." and "./out" all name /cwd/out; "." names /cwd and ".." its parent.
fs::path absoluteFolder(const std::string& path) {
  fs::path p = fs::absolute(fs::path(path)).lexically_normal();
  while (p.has_relative_path() && p.filename().empty()) p = p.parent_path();
  return p;
}

fs::path partialOf(const fs::path& out) {
  fs::path p = out;
  p += ".partial";
  return p;
}

std::string quoted(const std::string& path) { return path.empty() ? "''" : path; }

void requireWritableFolder(const fs::path& folder, const std::string& path, const std::string& option) {
  std::error_code ec;
  const fs::file_status st = fs::status(folder, ec);
  if (!fs::exists(st)) fail(path, option, "folder " + folder.string() + " does not exist");
  if (!fs::is_directory(st)) fail(path, option, folder.string() + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    fail(path, option, "cannot write into folder " + folder.string() + ": " + std::strerror(errno));
}

// The nearest existing folder above (or at) p: where the missing ones would be created.
fs::path nearestExisting(fs::path p) {
  std::error_code ec;
  while (!fs::exists(fs::symlink_status(p, ec)) && p.has_relative_path()) p = p.parent_path();
  return p;
}

bool isPidSuffix(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

// Why an existing DIR may not be removed whatever it holds: a link, a file, or a protected folder; "" otherwise.
std::string whyNeverRemoved(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(dir, ec);
  if (fs::is_symlink(link)) return "is a symbolic link: give the folder it points to";
  if (!fs::is_directory(link)) return "is a file, not a folder";
  if (std::string why = protectedFolderReason(dir); !why.empty()) return "is " + why + ", which is never replaced";
  return "";
}

void removeAll(const fs::path& dir, const std::string& option, const char* what) {
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (ec) fail(dir.string(), option, std::string("cannot remove ") + what + ": " + ec.message());
}

// Swaps two existing folders in one step; false where the file system (or kernel) cannot.
bool exchange(const fs::path& a, const fs::path& b, const std::string& option) {
#ifdef RENAME_EXCHANGE
  if (::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0) return true;
  if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP)
    fail(b.string(), option, "cannot replace it with " + a.string() + ": " + std::strerror(errno));
#else
  (void)a, (void)b, (void)option;
#endif
  return false;
}

void renameOrFail(const fs::path& from, const fs::path& to, const std::string& option) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) fail(to.string(), option, "cannot rename " + from.string() + " to it: " + ec.message());
}

}  // namespace

void checkOutputFile(const std::string& path, const std::string& option) {
  if (path.empty()) return;
  const fs::path p(path);
  if (!p.has_filename() || p.filename() == "." || p.filename() == "..")
    fail(path, option, "names a folder, not a file");
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (fs::is_directory(st)) fail(path, option, "is a folder, not a file");
  if (fs::exists(st) && !fs::is_regular_file(st)) fail(path, option, "is not a regular file");
  requireWritableFolder(p.has_parent_path() ? p.parent_path() : fs::path("."), path, option);
}

void checkOutputFolder(const std::string& path, const std::string& option) {
  if (path.empty()) fail(quoted(path), option, "is an empty path");
  const fs::path dir = absoluteFolder(path);
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) fail(path, option, "is a file, not a folder");
  const fs::path existing = nearestExisting(dir);
  requireWritableFolder(existing, path, option);
}

std::string protectedFolderReason(const fs::path& dir) {
  std::error_code ec;
  const fs::path target = fs::canonical(dir, ec);
  if (ec) return "";
  if (target == target.root_path()) return "the root folder";
  if (const char* home = std::getenv("HOME"); home && *home) {
    const fs::path h = fs::canonical(home, ec);
    if (!ec && h == target) return "the home folder";
  }
  const fs::path cwd = fs::canonical(fs::current_path(ec), ec);
  if (ec) return "";
  if (cwd == target) return "the working folder";
  for (fs::path p = cwd; p.has_relative_path(); p = p.parent_path())
    if (p.parent_path() == target) return "an ancestor of the working folder";
  return "";
}

bool isStagingLeftover(const std::string& name) {
  if (name == kPartialMarker || name == kPreviousFolder) return true;
  const std::size_t at = name.rfind(".tmp.");
  return at != std::string::npos && at > 0 && isPidSuffix(name.substr(at + 5));
}

fs::path StagedFolder::check(const std::string& out, const StagingRules& rules) {
  const std::string& option = rules.option;
  if (out.empty()) fail(quoted(out), option, "is an empty path");
  const fs::path dir = absoluteFolder(out);
  if (!dir.has_relative_path()) fail(out, option, "is the root folder, which is never replaced");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(dir, ec))) {
    if (std::string why = whyNeverRemoved(dir); !why.empty()) fail(out, option, why);
    if (!rules.may_replace) fail(out, option, "already exists (" + rules.replace_hint + ")");
    if (std::string why = rules.replaceable(dir); !why.empty())
      fail(out, option, rules.refusal.empty() ? why : why + "; " + rules.refusal);
  }
  // A leftover OUT.partial goes when it carries the marker, or is a complete output whose marker was already
  // removed when the command was killed just before renaming it.
  const fs::path partial = partialOf(dir);
  if (fs::exists(fs::symlink_status(partial, ec))) {
    std::string why = whyNeverRemoved(partial);
    if (why.empty() && !fs::exists(fs::symlink_status(partial / kPartialMarker, ec))) why = rules.replaceable(partial);
    if (!why.empty())
      fail(partial.string(), option,
           "is in the way and not what an interrupted drover leaves (it " + why + "): remove it or choose another " +
               option);
  }
  requireWritableFolder(nearestExisting(dir.parent_path()), out, option);
  return dir;
}

StagedFolder::StagedFolder(const std::string& out, const StagingRules& rules)
    : out_(check(out, rules)), partial_(partialOf(out_)), option_(rules.option) {
  removeAll(partial_, option_, "the leftover of an interrupted run");
  std::error_code ec;
  fs::create_directories(partial_, ec);
  if (ec) fail(partial_.string(), option_, "cannot create folder: " + ec.message());
  std::ofstream marker(partial_ / kPartialMarker);
  marker << "Being written by drover; renamed to " << out_.filename().string() << " when complete.\n";
  if (!marker.flush()) fail((partial_ / kPartialMarker).string(), option_, "cannot write (disk full?)");
}

StagedFolder::~StagedFolder() {
  if (published_) return;
  std::error_code ec;
  fs::remove_all(partial_, ec);
}

void StagedFolder::publish() {
  std::error_code ec;
  fs::remove(partial_ / kPartialMarker, ec);
  if (!fs::exists(fs::symlink_status(out_, ec))) {
    renameOrFail(partial_, out_, option_);
  } else if (exchange(partial_, out_, option_)) {
    removeAll(partial_, option_, "the replaced folder");  // now holds the earlier OUT
  } else {
    replaceByParking(partial_, out_, option_);
  }
  published_ = true;
}

void replaceByParking(const fs::path& partial, const fs::path& out, const std::string& option) {
  renameOrFail(out, partial / kPreviousFolder, option);
  renameOrFail(partial, out, option);
  removeAll(out / kPreviousFolder, option, "the replaced folder");
}

}  // namespace drover::io
