// The progress observer of the module's algorithms: VTK's executive calls UpdateProgress(1.0)
// after RequestData whether the update was aborted or not, and UpdateProgress is not virtual,
// so an observer is the one place where an algorithm can drop it.
#pragma once

#include "vtkProgressObserver.h"

#include <functional>

namespace mlr
{

/// Hands every progress report to a function (which may drop it).
class ProgressForwarder : public vtkProgressObserver
{
public:
  static ProgressForwarder* New()
  {
    auto* result = new ProgressForwarder;
    result->InitializeObjectBase();
    return result;
  }
  void UpdateProgress(double amount) override
  {
    if (this->Report)
    {
      this->Report(amount);
    }
  }
  std::function<void(double)> Report;
};

} // namespace mlr
