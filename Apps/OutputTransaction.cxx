#include "OutputTransaction.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <stdexcept>

namespace fs = std::filesystem;

namespace mlr::cli
{

bool isSeriesFile(const std::string& name, const std::string& prefix, const std::string& suffix)
{
  return name.size() > prefix.size() + suffix.size() &&
    name.compare(0, prefix.size(), prefix) == 0 &&
    name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0 &&
    std::all_of(name.begin() + static_cast<long>(prefix.size()),
      name.end() - static_cast<long>(suffix.size()),
      [](unsigned char c) { return std::isdigit(c) != 0; });
}

namespace
{
/// The endings of the hidden names of a staged file and of an earlier file set aside.
constexpr const char* StagedEnding = ".partial";
constexpr const char* AsideEnding = ".earlier";

fs::path hiddenName(const fs::path& finalPath, const std::string& ending)
{
  return finalPath.parent_path() / ("." + finalPath.filename().string() + ending);
}
}

std::string OutputTransaction::shownNameOf(const std::string& name)
{
  for (const std::string ending : { StagedEnding, AsideEnding })
  {
    if (name.size() > 1 + ending.size() && name[0] == '.' &&
      name.compare(name.size() - ending.size(), ending.size(), ending) == 0)
    {
      return name.substr(1, name.size() - 1 - ending.size());
    }
  }
  return {};
}

OutputTransaction::OutputTransaction()
  : Started(fs::file_time_type::clock::now())
{
}

OutputTransaction::~OutputTransaction()
{
  if (!this->Committed)
  {
    this->moveBack();
    this->rollback();
  }
}

fs::path OutputTransaction::temporaryOf(const fs::path& finalPath)
{
  return hiddenName(finalPath, StagedEnding);
}

void OutputTransaction::createDirectories(const fs::path& directory)
{
  if (directory.empty())
  {
    return;
  }
  // Remember each level that is missing, outermost first, to undo them innermost first.
  std::vector<fs::path> missing;
  for (fs::path p = directory; !p.empty() && !fs::exists(p); p = p.parent_path())
  {
    missing.insert(missing.begin(), p);
    if (p == p.parent_path())
    {
      break;
    }
  }
  std::error_code error;
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(directory))
  {
    throw std::runtime_error("cannot create the directory '" + directory.string() +
      "': " + (error ? error.message() : "a file of that name is in the way"));
  }
  this->CreatedDirectories.insert(this->CreatedDirectories.end(), missing.begin(), missing.end());
}

fs::path OutputTransaction::stage(const fs::path& finalPath)
{
  // Two files staged under one name would share a temporary file, and the second rename
  // would fail after the first had replaced the earlier file.
  if (!this->StagedNames.insert(stagedName(finalPath)).second)
  {
    throw std::runtime_error(
      "'" + finalPath.string() + "' would be written twice in one run: nothing was written");
  }
  fs::path temporary = temporaryOf(finalPath);
  this->StagedFiles.push_back({ temporary, finalPath });
  return temporary;
}

void OutputTransaction::replaceSeries(
  const fs::path& directory, const std::string& prefix, const std::string& suffix)
{
  this->ReplacedSeries.push_back({ directory, prefix, suffix });
}

void OutputTransaction::removeAtCommit(
  const fs::path& file, std::function<bool(const fs::path&)> isStale)
{
  this->RemovedFiles.push_back({ file, std::move(isStale) });
}

void OutputTransaction::keep(const fs::path& finalPath)
{
  this->KeptFiles.push_back(finalPath);
}

void OutputTransaction::commit()
{
  this->moveIntoPlace();
  this->finish();
}

void OutputTransaction::moveBack() noexcept
{
  std::error_code ignored;
  for (std::size_t i = 0; i < this->Renamed; ++i)
  {
    fs::rename(this->StagedFiles[i].final, this->StagedFiles[i].temporary, ignored);
  }
  for (const auto& [final, aside] : this->Asides)
  {
    fs::rename(aside, final, ignored);
  }
  this->Renamed = 0;
  this->Asides.clear();
}

void OutputTransaction::moveIntoPlace()
{
  // The earlier files of these names step aside first, under hidden names, and come back if
  // any rename fails: a failure halfway must not leave the new run's first frames beside the
  // earlier run's last ones and its .pvd.
  for (const Staged& file : this->StagedFiles)
  {
    std::error_code error;
    if (fs::is_regular_file(file.final, error))
    {
      const fs::path aside = hiddenName(file.final, AsideEnding);
      fs::rename(file.final, aside, error);
      if (error)
      {
        this->moveBack();
        throw std::runtime_error("cannot replace '" + file.final.string() +
          "': " + error.message() + ": the earlier files are kept, nothing was written");
      }
      this->Asides.emplace_back(file.final, aside);
    }
  }
  for (const Staged& file : this->StagedFiles)
  {
    std::error_code error;
    fs::rename(file.temporary, file.final, error);
    if (error)
    {
      this->moveBack();
      throw std::runtime_error("cannot rename '" + file.temporary.string() + "' to '" +
        file.final.string() + "': " + error.message() +
        ": the earlier files are kept, nothing was written");
    }
    ++this->Renamed;
  }
}

void OutputTransaction::finish()
{
  this->Committed = true;
  for (const auto& [final, aside] : this->Asides)
  {
    std::error_code ignored;
    fs::remove(aside, ignored);
  }
  this->Asides.clear();

  std::set<fs::path> kept;
  for (const Staged& file : this->StagedFiles)
  {
    kept.insert(file.final.lexically_normal());
  }
  for (const fs::path& file : this->KeptFiles)
  {
    kept.insert(file.lexically_normal());
  }
  for (const Series& series : this->ReplacedSeries)
  {
    std::error_code error;
    const fs::path directory = series.directory.empty() ? fs::path(".") : series.directory;
    for (const fs::directory_entry& entry : fs::directory_iterator(directory, error))
    {
      const std::string name = entry.path().filename().string();
      const fs::path path = (series.directory / name).lexically_normal();
      if (isSeriesFile(name, series.prefix, series.suffix) && entry.is_regular_file() &&
        kept.count(path) == 0)
      {
        fs::remove(entry.path(), error);
      }
      // What a run killed before it could clean up (SIGKILL, out of memory) left of this
      // series: its staged files and the earlier ones it set aside. Every process that
      // commits with this one has renamed its own by now; those of another run writing the
      // same series now are newer than this transaction, and stay.
      else if (isSeriesFile(shownNameOf(name), series.prefix, series.suffix) &&
        entry.is_regular_file() && entry.last_write_time(error) < this->Started && !error)
      {
        fs::remove(entry.path(), error);
      }
    }
  }
  for (const Removal& removal : this->RemovedFiles)
  {
    std::error_code error;
    if (kept.count(removal.file.lexically_normal()) == 0 &&
      fs::is_regular_file(removal.file, error) &&
      (!removal.isStale || removal.isStale(removal.file)))
    {
      fs::remove(removal.file, error);
    }
  }
}

void OutputTransaction::rollback() noexcept
{
  std::error_code error;
  for (const Staged& file : this->StagedFiles)
  {
    fs::remove(file.temporary, error);
  }
  for (auto d = this->CreatedDirectories.rbegin(); d != this->CreatedDirectories.rend(); ++d)
  {
    fs::remove(*d, error); // only succeeds while empty, which is what we want
  }
}

} // namespace mlr::cli
