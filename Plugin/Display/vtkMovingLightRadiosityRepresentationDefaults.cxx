#include "vtkMovingLightRadiosityRepresentationDefaults.h"

#include "vtkDataObject.h"
#include "vtkObjectFactory.h"
#include "vtkPVXMLElement.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <cstring>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkMovingLightRadiosityRepresentationDefaults);

//------------------------------------------------------------------------------
void vtkMovingLightRadiosityRepresentationDefaults::PostInitializeProxy(
  vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp)
{
  if (!proxy || !xml)
  {
    return;
  }
  for (unsigned int i = 0; i < xml->GetNumberOfNestedElements(); ++i)
  {
    vtkPVXMLElement* element = xml->GetNestedElement(i);
    const char* tag = element->GetName();
    const bool colorBy = std::strcmp(tag, "ColorBy") == 0;
    const char* name = colorBy ? "ColorArrayName" : element->GetAttribute("name");
    if (!colorBy && (std::strcmp(tag, "Property") != 0 || !name))
    {
      vtkWarningMacro(<< "ignoring <" << tag << ">: expected <Property name=... value=...> or "
                      << "<ColorBy association=... array=...>");
      continue;
    }
    vtkSMProperty* property = proxy->GetProperty(name);
    if (!property)
    {
      vtkWarningMacro(<< proxy->GetXMLName() << " has no property " << name);
      continue;
    }
    if (property->GetMTime() > initializationTimeStamp)
    {
      continue; // set by the caller: theirs wins
    }
    if (colorBy)
    {
      const char* association = element->GetAttributeOrDefault("association", "POINTS");
      const int field = std::strcmp(association, "CELLS") == 0
        ? vtkDataObject::FIELD_ASSOCIATION_CELLS
        : vtkDataObject::FIELD_ASSOCIATION_POINTS;
      vtkSMPropertyHelper(property).SetInputArrayToProcess(
        field, element->GetAttributeOrDefault("array", ""));
      continue;
    }
    std::istringstream text(element->GetAttributeOrDefault("value", ""));
    std::vector<double> values;
    for (double v; text >> v;)
    {
      values.push_back(v);
    }
    if (values.empty())
    {
      vtkWarningMacro(<< "no numbers in value of property " << name);
      continue;
    }
    vtkSMPropertyHelper helper(property);
    if (property->IsA("vtkSMIntVectorProperty"))
    {
      std::vector<int> integers(values.begin(), values.end());
      helper.Set(integers.data(), static_cast<unsigned int>(integers.size()));
    }
    else
    {
      helper.Set(values.data(), static_cast<unsigned int>(values.size()));
    }
  }
  proxy->UpdateVTKObjects();
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosityRepresentationDefaults::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
