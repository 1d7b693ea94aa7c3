// A read-only virtual filesystem over game folders and their .pk4 (zip) archives, resolved the way
// idTech 4 does: within a folder the .pk4s are opened in sorted name order, a later archive overriding
// an earlier one, and loose files override archives; a search path added later overrides earlier ones
// (a mod folder added after base/). Names are looked up case-insensitively with '/' separators.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cohort::scene {

class Vfs {
 public:
  Vfs();
  ~Vfs();
  Vfs(const Vfs&) = delete;
  Vfs& operator=(const Vfs&) = delete;

  // Adds a game folder: its loose files and every .pk4 directly inside it. Throws std::runtime_error
  // when the folder does not exist or an archive cannot be opened.
  void add_search_path(const std::filesystem::path& folder);
  // Adds one archive on top of everything added so far.
  void add_archive(const std::filesystem::path& pk4);

  bool exists(std::string_view name) const;
  // The file's bytes, or nothing when no search path has it. Throws when an archive entry is unreadable.
  std::optional<std::string> read(std::string_view name) const;
  // Where a name comes from, for messages: a disk path, or "archive.pk4:entry"; the name itself if absent.
  std::string describe(std::string_view name) const;
  // Names (as stored, sorted case-insensitively) of the files directly or indirectly under folder whose
  // names end with extension (e.g. list("materials", ".mtr")).
  std::vector<std::string> list(std::string_view folder, std::string_view extension) const;

  size_t file_count() const { return index_.size(); }
  const std::vector<std::filesystem::path>& search_paths() const { return search_paths_; }

  // Lower case, '/' separators, no leading "./" or '/'.
  static std::string normalize(std::string_view name);

 private:
  struct Archive;
  struct Entry {
    std::string stored_name;       // as the folder or archive spells it
    std::filesystem::path disk_path;  // loose file; empty for archive entries
    int archive = -1;
    uint64_t zip_index = 0;
  };

  std::vector<std::unique_ptr<Archive>> archives_;
  std::map<std::string, Entry> index_;  // by normalized name
  std::vector<std::filesystem::path> search_paths_;
};

}  // namespace cohort::scene
