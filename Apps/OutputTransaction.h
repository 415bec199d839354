// A set of output files that appears all at once or not at all.
#pragma once

#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace mlr::cli
{

/// Whether the file name `name` is `prefix`, one or more digits and `suffix`: a file of a
/// series (OutputTransaction::replaceSeries deletes those it did not write).
bool isSeriesFile(const std::string& name, const std::string& prefix, const std::string& suffix);

/**
 * Files are written under hidden temporary names next to their final ones and renamed when
 * commit() is called; until then, destroying the transaction (an error, an exception) removes
 * them, and the directories it created, so that a failure never leaves a half-written series
 * and never touches an earlier one. Renames happen in staging order: stage the index file
 * (.pvd) last so that it never names a frame that is not there yet.
 */
class OutputTransaction
{
public:
  OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();

  /// Creates `directory` and its missing parents (removed again on rollback if still empty).
  void createDirectories(const std::filesystem::path& directory);

  /// The temporary path to write the file that becomes `finalPath` at commit.
  std::filesystem::path stage(const std::filesystem::path& finalPath);

  /// At commit, also delete the files of `directory` named `prefix` + digits + `suffix` that
  /// were not staged: the frames of an earlier, longer series of the same name; and the
  /// hidden files of such names that a killed run staged or set aside (older than this
  /// transaction).
  void replaceSeries(
    const std::filesystem::path& directory, const std::string& prefix, const std::string& suffix);

  /// At commit, also delete `file` if it is a regular file that was not staged: the index of
  /// a series this run no longer writes. `isStale`, if given, must say yes first (it is given
  /// the file's path).
  void removeAtCommit(const std::filesystem::path& file,
    std::function<bool(const std::filesystem::path&)> isStale = {});

  /// A file of a replaced series that another process writes and commits before this one:
  /// kept, though not staged here.
  void keep(const std::filesystem::path& finalPath);

  /// Renames every staged file to its final name. Throws std::runtime_error on failure.
  void commit();

  /// commit() in two steps, for processes that commit together (MPI ranks): moveIntoPlace()
  /// renames the staged files, the earlier ones set aside (undone, and an error thrown, if
  /// any rename fails); finish() then drops the earlier files and the replaced series' rest.
  /// Until finish(), destroying the transaction moves every file back: when another process
  /// failed, this one's earlier files return too.
  void moveIntoPlace();
  void finish();

  /// Whether this transaction staged `finalPath`.
  bool stages(const std::filesystem::path& finalPath) const
  {
    return this->StagedNames.count(stagedName(finalPath)) > 0;
  }

  /// The hidden name stage() writes `finalPath` under.
  static std::filesystem::path temporaryOf(const std::filesystem::path& finalPath);

  /// The file name that the hidden file name `name` of a transaction stands for (.NAME.partial
  /// staged, .NAME.earlier set aside: NAME), empty for any other name.
  static std::string shownNameOf(const std::string& name);

private:
  struct Staged
  {
    std::filesystem::path temporary, final;
  };
  struct Series
  {
    std::filesystem::path directory;
    std::string prefix, suffix;
  };
  void rollback() noexcept;
  void moveBack() noexcept;
  /// A staged file's key in StagedNames.
  static std::filesystem::path stagedName(const std::filesystem::path& finalPath)
  {
    return std::filesystem::absolute(finalPath).lexically_normal();
  }

  std::vector<Staged> StagedFiles;
  std::set<std::filesystem::path> StagedNames; ///< absolute, normalised
  struct Removal
  {
    std::filesystem::path file;
    std::function<bool(const std::filesystem::path&)> isStale;
  };
  std::vector<Series> ReplacedSeries;
  std::vector<Removal> RemovedFiles;
  std::vector<std::filesystem::path> KeptFiles;
  std::vector<std::filesystem::path> CreatedDirectories;
  /// Of moveIntoPlace(): the files renamed (the first of StagedFiles), and the earlier
  /// files set aside (final name, hidden name).
  std::size_t Renamed = 0;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> Asides;
  bool Committed = false;
  /// When the transaction began: hidden files of its series older than this are a killed
  /// run's.
  std::filesystem::file_time_type Started;
};

} // namespace mlr::cli
