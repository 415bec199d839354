// The fuzz target of the readers uses Apps/InputFiles.cxx without the Cornell box compiled in.
#include "EmbeddedData.h"

#include <stdexcept>

namespace mlr::cli
{

std::string embeddedDataFile(const std::string& name)
{
  throw std::out_of_range("no embedded file " + name + " in the fuzz target");
}

} // namespace mlr::cli
