#include "vtkMovingLightRadiosityRepresentationDefaults.h"

#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVXMLElement.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSettings.h"
#include "vtkSMTransferFunctionPresets.h"

#include "vtkMovingLightRadiosityPresets.h"
#include "vtk_jsoncpp.h"

#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkMovingLightRadiosityRepresentationDefaults);

namespace
{
// ParaView reads an array's colour map from its settings when it first makes the array's lookup
// table (vtkSMTransferFunctionManager): the preset named by .standard_presets.<array>, then the
// properties under .array_lookup_tables.<array>.PVLookupTable, and the scalar bar's title from
// .array_lookup_tables.<array>.Title. The plugin adds them as a settings collection of its own
// below the user's, so that a user's settings still win and nothing is written to their file.
constexpr double ColorMapSettingsPriority = 0.5;

// The arrays whose colour maps are in the settings already: one collection each per process.
std::set<std::string> ColorMapArrays;

// Map Scalars follows the colour array: off for an array of display colours, on for one of
// values, or colouring by Illuminance would show its lux as colour bytes.
class MapScalarsByArray : public vtkCommand
{
public:
  static MapScalarsByArray* New() { return new MapScalarsByArray; }
  std::map<std::string, int> MapScalars;
  vtkSMProxy* Proxy = nullptr; // owns the observed property, so outlives this observer

  void Execute(vtkObject* caller, unsigned long, void*) override
  {
    auto* property = vtkSMProperty::SafeDownCast(caller);
    if (!property || !this->Proxy)
    {
      return;
    }
    const char* array = vtkSMPropertyHelper(property).GetInputArrayNameToProcess();
    const auto found = this->MapScalars.find(array ? array : "");
    if (found != this->MapScalars.end())
    {
      vtkSMPropertyHelper(this->Proxy, "MapScalars").Set(found->second);
    }
  }
};

bool RegisterPreset(const char* name)
{
  vtkSMTransferFunctionPresets* presets = vtkSMTransferFunctionPresets::GetInstance();
  if (presets->HasPreset(name))
  {
    return true;
  }
  Json::Value all;
  Json::CharReaderBuilder builder;
  std::istringstream text(mlrColorMapPresets);
  std::string errors;
  if (!Json::parseFromStream(builder, text, &all, &errors) || !all.isArray())
  {
    return false;
  }
  for (const Json::Value& preset : all)
  {
    if (preset["Name"].asString() == name)
    {
      return presets->AddPreset(name, preset);
    }
  }
  return false;
}
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosityRepresentationDefaults::PostInitializeProxy(
  vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp)
{
  if (!proxy || !xml)
  {
    return;
  }
  vtkNew<MapScalarsByArray> mapScalars;
  for (unsigned int i = 0; i < xml->GetNumberOfNestedElements(); ++i)
  {
    vtkPVXMLElement* element = xml->GetNestedElement(i);
    const char* tag = element->GetName();
    const bool colorMap = std::strcmp(tag, "ColorMap") == 0;
    const bool colorBy = std::strcmp(tag, "ColorBy") == 0;
    int mapScalarsValue = 0;
    if ((colorMap || colorBy) && element->GetScalarAttribute("map_scalars", &mapScalarsValue))
    {
      mapScalars->MapScalars[element->GetAttributeOrDefault("array", "")] = mapScalarsValue;
    }
    if (colorMap)
    {
      this->AddColorMap(element);
      continue;
    }
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
  vtkSMProperty* colorArray = proxy->GetProperty("ColorArrayName");
  if (!mapScalars->MapScalars.empty() && colorArray && proxy->GetProperty("MapScalars"))
  {
    mapScalars->Proxy = proxy;
    colorArray->AddObserver(vtkCommand::ModifiedEvent, mapScalars);
  }
  proxy->UpdateVTKObjects();
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosityRepresentationDefaults::AddColorMap(vtkPVXMLElement* element)
{
  const char* array = element->GetAttribute("array");
  if (!array || !*array)
  {
    vtkWarningMacro(<< "ignoring <ColorMap> without an array");
    return;
  }
  if (!ColorMapArrays.insert(array).second)
  {
    return; // every representation made after the first finds it in the settings already
  }
  const char* preset = element->GetAttribute("preset");
  Json::Value settings(Json::objectValue);
  if (preset)
  {
    if (RegisterPreset(preset))
    {
      settings["standard_presets"][array] = preset;
    }
    else
    {
      vtkWarningMacro(<< "the plugin has no colour map preset " << preset);
    }
  }
  int logScale = 0;
  if (element->GetScalarAttribute("log_scale", &logScale))
  {
    settings["array_lookup_tables"][array]["PVLookupTable"]["UseLogScale"] = logScale;
  }
  if (const char* title = element->GetAttribute("title"))
  {
    settings["array_lookup_tables"][array]["Title"] = title;
  }
  vtkSMSettings::GetInstance()->AddCollectionFromString(
    Json::writeString(Json::StreamWriterBuilder(), settings), ColorMapSettingsPriority);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosityRepresentationDefaults::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
