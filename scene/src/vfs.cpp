#include "cohort/scene/vfs.h"

#include <zip.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "ascii_case.h"

namespace cohort::scene {

namespace fs = std::filesystem;

namespace {

// Nothing in a Doom 3 game folder comes near this; a larger entry is a damaged or hostile archive.
constexpr uint64_t kMaxFileBytes = 1ull << 30;

}  // namespace

struct Vfs::Archive {
  fs::path path;
  zip_t* zip = nullptr;
  ~Archive() {
    if (zip) zip_discard(zip);
  }
};

Vfs::Vfs() = default;
Vfs::~Vfs() = default;

std::string Vfs::normalize(std::string_view name) {
  std::string out;
  out.reserve(name.size());
  for (char c : name) out.push_back(c == '\\' ? '/' : ascii_lower(c));
  while (out.rfind("./", 0) == 0) out.erase(0, 2);
  while (!out.empty() && out.front() == '/') out.erase(0, 1);
  return out;
}

void Vfs::add_archive(const fs::path& pk4) {
  int error = 0;
  zip_t* zip = zip_open(pk4.string().c_str(), ZIP_RDONLY, &error);
  if (!zip) {
    zip_error_t ze;
    zip_error_init_with_code(&ze, error);
    std::string why = zip_error_strerror(&ze);
    zip_error_fini(&ze);
    throw std::runtime_error(pk4.string() + ": cannot open archive: " + why);
  }
  auto archive = std::make_unique<Archive>();
  archive->path = pk4;
  archive->zip = zip;
  int archive_id = static_cast<int>(archives_.size());
  zip_int64_t count = zip_get_num_entries(zip, 0);
  for (zip_int64_t i = 0; i < count; ++i) {
    const char* name = zip_get_name(zip, static_cast<zip_uint64_t>(i), ZIP_FL_ENC_GUESS);
    if (!name) continue;
    std::string_view stored(name);
    if (stored.empty() || stored.back() == '/') continue;  // folder entries
    Entry e;
    e.stored_name = std::string(stored);
    e.archive = archive_id;
    e.zip_index = static_cast<uint64_t>(i);
    index_[normalize(stored)] = std::move(e);
  }
  archives_.push_back(std::move(archive));
}

void Vfs::add_search_path(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw std::runtime_error(folder.string() + ": not a folder");
  search_paths_.push_back(folder);

  std::vector<fs::path> pk4s;
  for (const auto& item : fs::directory_iterator(folder, fs::directory_options::skip_permission_denied, ec))
    if (item.is_regular_file(ec) && ends_with_ignoring_case(item.path().filename().string(), ".pk4"))
      pk4s.push_back(item.path());
  std::sort(pk4s.begin(), pk4s.end(),
            [](const fs::path& a, const fs::path& b) { return a.filename().string() < b.filename().string(); });
  for (const auto& pk4 : pk4s) add_archive(pk4);

  auto it = fs::recursive_directory_iterator(folder, fs::directory_options::skip_permission_denied, ec);
  for (; !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    std::string relative = fs::relative(it->path(), folder, ec).generic_string();
    if (ec || relative.empty()) continue;
    if (ends_with_ignoring_case(relative, ".pk4") && relative.find('/') == std::string::npos) continue;
    Entry e;
    e.stored_name = relative;
    e.disk_path = it->path();
    index_[normalize(relative)] = std::move(e);
  }
}

bool Vfs::exists(std::string_view name) const { return index_.count(normalize(name)) != 0; }

std::optional<std::string> Vfs::read(std::string_view name) const {
  auto found = index_.find(normalize(name));
  if (found == index_.end()) return std::nullopt;
  const Entry& e = found->second;
  if (e.archive < 0) {
    std::ifstream in(e.disk_path, std::ios::binary);
    if (!in) throw std::runtime_error(e.disk_path.string() + ": cannot read");
    std::error_code ec;
    uint64_t size = fs::file_size(e.disk_path, ec);
    if (ec || size > kMaxFileBytes) throw std::runtime_error(e.disk_path.string() + ": unreadable or too large");
    std::string bytes(static_cast<size_t>(size), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(size));
    bytes.resize(static_cast<size_t>(in.gcount()));
    return bytes;
  }
  const Archive& archive = *archives_[static_cast<size_t>(e.archive)];
  std::string where = archive.path.string() + ":" + e.stored_name;
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(archive.zip, e.zip_index, 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
    throw std::runtime_error(where + ": cannot stat archive entry");
  if (st.size > kMaxFileBytes) throw std::runtime_error(where + ": archive entry too large");
  zip_file_t* file = zip_fopen_index(archive.zip, e.zip_index, 0);
  if (!file) throw std::runtime_error(where + ": cannot open archive entry: " + zip_strerror(archive.zip));
  std::string bytes(static_cast<size_t>(st.size), '\0');
  zip_int64_t got = bytes.empty() ? 0 : zip_fread(file, bytes.data(), bytes.size());
  zip_fclose(file);
  if (got < 0 || static_cast<uint64_t>(got) != st.size)
    throw std::runtime_error(where + ": archive entry is damaged (read " + std::to_string(got) + " of " +
                             std::to_string(st.size) + " bytes)");
  return bytes;
}

std::string Vfs::describe(std::string_view name) const {
  auto found = index_.find(normalize(name));
  if (found == index_.end()) return std::string(name);
  const Entry& e = found->second;
  if (e.archive < 0) return e.disk_path.string();
  return archives_[static_cast<size_t>(e.archive)]->path.string() + ":" + e.stored_name;
}

std::vector<std::string> Vfs::list(std::string_view folder, std::string_view extension) const {
  std::string prefix = normalize(folder);
  if (!prefix.empty() && prefix.back() != '/') prefix.push_back('/');
  std::vector<std::string> out;
  for (auto it = index_.lower_bound(prefix); it != index_.end() && it->first.rfind(prefix, 0) == 0; ++it)
    if (ends_with_ignoring_case(it->first, extension)) out.push_back(it->second.stored_name);
  return out;
}

}  // namespace cohort::scene
