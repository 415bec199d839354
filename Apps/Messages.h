// How VTK's errors and warnings reach the user of the command line: one line each, on
// stderr, prefixed with the program name, without source locations or object addresses.
#pragma once

#include <cstddef>
#include <string>

namespace mlr::cli
{

/// Routes VTK's messages through a condensed output window. Call once, first thing.
void installMessageWindow(const std::string& program);

/// VTK errors reported so far (those shown and those dropped as repetitions).
std::size_t vtkErrorCount();

/// The last VTK error reported, condensed (empty when none).
const std::string& lastVtkError();

/// From now on nothing is printed: under mpiexec, on the ranks other than 0.
void quietMessages();

/// The program aborts the filter itself (an interrupt, a frame it could not write): the
/// filter's error that it was cancelled is not printed, since the program's own reason follows.
void abortingTheFilter();

/// Prints "program: error: message" on stderr.
void printError(const std::string& message);

/// Prints "program: warning: message" on stderr.
void printWarning(const std::string& message);

} // namespace mlr::cli
