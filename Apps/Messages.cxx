#include "Messages.h"

#include "Error.h"

#include "vtkLogger.h"
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"
#include "vtkSmartPointer.h"

#include <atomic>
#include <iostream>

namespace mlr::cli
{

namespace
{
std::string Program = "moving-light-radiosity";
std::size_t Errors = 0;
std::string LastError;
bool Quiet = false;
std::atomic<bool> Aborting{ false };

/// "ERROR: In file.cxx, line 12\nvtkSomething (0x1234): what went wrong\n\n" -> "what went wrong"
std::string condensed(std::string text)
{
  if (text.rfind("ERROR: In ", 0) == 0 || text.rfind("Warning: In ", 0) == 0)
  {
    const std::size_t newline = text.find('\n');
    text = newline == std::string::npos ? std::string() : text.substr(newline + 1);
  }
  const std::size_t address = text.find(" (0x");
  const std::size_t colon = text.find("): ");
  if (address != std::string::npos && colon != std::string::npos && address < colon &&
    text.find(' ') == address)
  {
    text = text.substr(colon + 3);
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' '))
  {
    text.pop_back();
  }
  return text;
}

class CondensedOutputWindow : public vtkOutputWindow
{
public:
  static CondensedOutputWindow* New();
  vtkTypeMacro(CondensedOutputWindow, vtkOutputWindow);

  void DisplayErrorText(const char* text) override
  {
    ++Errors;
    const std::string message = condensed(text);
    if (message.find("returned failure for request") == std::string::npos)
    {
      LastError = message;
    }
    // The executive repeats every failed request with a dump of its pipeline information;
    // the algorithm's own error already said what is wrong.
    if (message.find("returned failure for request") == std::string::npos &&
      !(Aborting && message.find(mlr::Cancelled().what()) != std::string::npos))
    {
      printError(message);
    }
  }
  void DisplayWarningText(const char* text) override
  {
    if (!Quiet)
    {
      std::cerr << Program << ": warning: " << condensed(text) << std::endl;
    }
  }
  void DisplayGenericWarningText(const char* text) override { this->DisplayWarningText(text); }
  void DisplayText(const char* text) override
  {
    if (!Quiet)
    {
      std::cerr << condensed(text) << std::endl;
    }
  }
  void DisplayDebugText(const char*) override {}

protected:
  CondensedOutputWindow() = default;
};
vtkStandardNewMacro(CondensedOutputWindow);
}

void installMessageWindow(const std::string& program)
{
  Program = program;
  // vtkLogger would print every message a second time, with its own decorations.
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  vtkOutputWindow::SetInstance(vtkSmartPointer<CondensedOutputWindow>::New());
}

std::size_t vtkErrorCount()
{
  return Errors;
}

const std::string& lastVtkError()
{
  return LastError;
}

void quietMessages()
{
  Quiet = true;
}

void abortingTheFilter()
{
  Aborting = true;
}

void printError(const std::string& message)
{
  if (Quiet)
  {
    return;
  }
  std::cerr << Program << ": error: " << message << std::endl;
}

void printWarning(const std::string& message)
{
  if (Quiet)
  {
    return;
  }
  std::cerr << Program << ": warning: " << message << std::endl;
}

} // namespace mlr::cli
