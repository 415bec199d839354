// Text, file and progress helpers the scene formats share (OBJ and MTL, glTF, PLY): how
// messages show names and pieces of a file, words and numbers as the files write them, opening
// a file with a FileError naming it, and the progress callback. Private to the Filters module.
#pragma once

#include "RadiositySceneFormats.h"
#include "TextLines.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace mlr::scenefile
{

/// `text` in quotes, as messages name files and materials.
std::string named(const std::string& text);

std::string trim(const std::string& text);

/// The words of `text`, split at white space.
std::vector<std::string> words(const std::string& text);

/// A whole word as a finite number (locale independent, as files are written).
bool parseNumber(const std::string& word, double& value);

bool parseInteger(const std::string& word, long long& value);

/// The size of the file `path` in bytes; 0 when it cannot be read.
std::uintmax_t fileSize(const std::string& path);

/// Opens `path` for reading or throws FileError naming `kind` ("OBJ file") and the reason.
std::ifstream openFile(const std::string& path, const std::string& kind);

/// Reads the progress callback every so many units of work, and stops on request.
class ProgressPoll
{
public:
  ProgressPoll(const Progress& progress, double from, double to)
    : Callback(progress)
    , From(from)
    , To(to)
  {
  }
  void operator()(double fraction)
  {
    if (this->Callback &&
      !this->Callback(this->From + (this->To - this->From) * std::clamp(fraction, 0.0, 1.0)))
    {
      throw Aborted{};
    }
  }

private:
  const Progress& Callback;
  double From, To;
};

} // namespace mlr::scenefile
