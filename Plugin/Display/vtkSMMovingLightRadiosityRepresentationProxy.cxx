#include "vtkSMMovingLightRadiosityRepresentationProxy.h"

#include "vtkClientServerStream.h"
#include "vtkObjectFactory.h"
#include "vtkPVArrayInformation.h"
#include "vtkSMCoreUtilities.h"
#include "vtkSMPropertyHelper.h"

#include <string>

vtkStandardNewMacro(vtkSMMovingLightRadiosityRepresentationProxy);

//------------------------------------------------------------------------------
vtkSMMovingLightRadiosityRepresentationProxy::vtkSMMovingLightRadiosityRepresentationProxy() =
  default;

//------------------------------------------------------------------------------
vtkSMMovingLightRadiosityRepresentationProxy::~vtkSMMovingLightRadiosityRepresentationProxy() =
  default;

//------------------------------------------------------------------------------
bool vtkSMMovingLightRadiosityRepresentationProxy::PositiveRangeForLog(double range[2])
{
  if (!(range[1] > 0))
  {
    return false;
  }
  // ParaView's own choice for a log scale whose data reach 0 (vtkSMCoreUtilities::
  // AdjustRangeForLog, which vtkSMTransferFunctionProxy applies after its warning): four
  // decades under the maximum, at most 1. The smallest value above 0 would be the other
  // choice, but a single element that a stray path barely reaches (1e-9 lx) would then stretch
  // the scale over 14 decades and leave the lit surfaces a few colours; ParaView's keeps what a
  // user who turns the log scale on in ParaView sees.
  vtkSMCoreUtilities::AdjustRangeForLog(range);
  return true;
}

//------------------------------------------------------------------------------
vtkPVArrayInformation* vtkSMMovingLightRadiosityRepresentationProxy::ForLogScale(
  vtkPVArrayInformation* info)
{
  vtkSMProxy* lut = vtkSMPropertyHelper(this, "LookupTable", true).GetAsProxy();
  if (!info || !lut || vtkSMPropertyHelper(lut, "UseLogScale", true).GetAsInt() == 0 ||
    vtkSMPropertyHelper(lut, "IndexedLookup", true).GetAsInt() != 0)
  {
    return info;
  }
  // The component ParaView's rescale reads (vtkSMPVRepresentationProxy,
  // vtkSMTransferFunctionProxy::ComputeDataRange): -1, the magnitude, unless by component.
  const int component = vtkSMPropertyHelper(lut, "VectorMode", true).GetAsInt() != 0
    ? vtkSMPropertyHelper(lut, "VectorComponent", true).GetAsInt()
    : -1;
  if (info->GetNumberOfComponents() == 0 || component >= info->GetNumberOfComponents())
  {
    return info;
  }
  double range[2];
  info->GetComponentFiniteRange(component, range);
  if (!(range[0] <= range[1]) || range[0] > 0)
  {
    return info; // no data, or a range a log scale can show
  }
  double positive[2] = { range[0], range[1] };
  if (!PositiveRangeForLog(positive))
  {
    positive[0] = 1; // nothing above 0: an empty range, which ParaView's rescale skips
    positive[1] = 0;
  }

  // vtkPVArrayInformation has no setter for a range: the copy goes through its stream, where
  // ParaView 5.11 writes the name, the data type, the tuple count, IsPartial, the count of
  // components (the magnitude first) and then each one's range, finite range, name and default
  // name. Only the finite range of `component` is written anew.
  vtkClientServerStream original;
  info->CopyToStream(&original);
  const int finiteRangeArgument = 5 + 4 * (component + 1) + 1;
  vtkClientServerStream copy;
  copy << vtkClientServerStream::Reply;
  for (int argument = 0; argument < original.GetNumberOfArguments(0); ++argument)
  {
    if (argument == finiteRangeArgument)
    {
      copy << vtkClientServerStream::InsertArray(positive, 2);
    }
    else if (bool flag = false;
             original.GetArgumentType(0, argument) == vtkClientServerStream::bool_value &&
             original.GetArgument(0, argument, &flag))
    {
      copy << flag; // an Argument copies no bool (ParaView 5.11)
    }
    else
    {
      copy << original.GetArgument(0, argument);
    }
  }
  copy << vtkClientServerStream::End;
  vtkPVArrayInformation* adjusted = this->LogScaleInformation;
  adjusted->Initialize();
  const auto same = [](const char* a, const char* b)
  { return std::string(a ? a : "") == (b ? b : ""); };
  bool copied = adjusted->CopyFromStream(&copy) &&
    adjusted->GetNumberOfComponents() == info->GetNumberOfComponents() &&
    adjusted->GetDataType() == info->GetDataType() &&
    adjusted->GetNumberOfTuples() == info->GetNumberOfTuples() &&
    same(adjusted->GetName(), info->GetName());
  if (copied)
  {
    double written[2];
    adjusted->GetComponentFiniteRange(component, written);
    copied = written[0] == positive[0] && written[1] == positive[1];
  }
  if (!copied)
  {
    vtkWarningMacro(<< "could not copy the information of array "
                    << (info->GetName() ? info->GetName() : "") << ": its log-scale colour map "
                    << "is rescaled as ParaView does");
    return info;
  }
  return adjusted;
}

//------------------------------------------------------------------------------
vtkPVArrayInformation*
vtkSMMovingLightRadiosityRepresentationProxy::GetArrayInformationForColorArray(
  bool checkRepresentedData)
{
  return this->ForLogScale(
    this->Superclass::GetArrayInformationForColorArray(checkRepresentedData));
}

//------------------------------------------------------------------------------
bool vtkSMMovingLightRadiosityRepresentationProxy::RescaleTransferFunctionToDataRange(
  vtkPVArrayInformation* info, bool extend, bool force)
{
  // Information from GetArrayInformationForColorArray is the log scale's already:
  // ForLogScale then returns it as it is.
  return this->Superclass::RescaleTransferFunctionToDataRange(
    this->ForLogScale(info), extend, force);
}

//------------------------------------------------------------------------------
void vtkSMMovingLightRadiosityRepresentationProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LogScaleInformation:\n";
  this->LogScaleInformation->PrintSelf(os, indent.GetNextIndent());
}
