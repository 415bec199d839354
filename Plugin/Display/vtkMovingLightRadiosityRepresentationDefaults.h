/**
 * @class   vtkMovingLightRadiosityRepresentationDefaults
 * @brief   representation property defaults given in a proxy's XML hints
 *
 * ParaView 5.11 has no XML hint for a filter to choose how its outputs are first shown
 * beyond the representation type; this initialization helper supplies one. A representation
 * proxy names it in its hints, with the values to start from:
 * \code{.xml}
 * <Hints>
 *   <InitializationHelper class="vtkMovingLightRadiosityRepresentationDefaults">
 *     <Property name="MapScalars" value="0" />
 *     <Property name="DiffuseColor" value="1 0.85 0.2" />
 *     <ColorBy association="POINTS" array="Color" />  <!-- array="" : solid colour -->
 *   </InitializationHelper>
 * </Hints>
 * \endcode
 * A <ColorMap array="Illuminance" preset="Illuminance (lux, log)" log_scale="1"
 * title="Illuminance (lx)" /> gives the lookup table ParaView makes for that array, whichever
 * representation colours by it first, the named preset (one of IlluminancePresets.json, which
 * the plugin registers), log scale and the scalar bar's title. The range stays ParaView's: the
 * data's range at the time, a minimum of 0 raised to 1e-4 of the maximum but at most 1 (which
 * vtkSMMovingLightRadiosityRepresentationProxy gives without ParaView's warning).
 * It only changes what colouring by the array looks like: ColorBy still chooses the array.
 * map_scalars="0|1" on a <ColorBy> or a <ColorMap> sets Map Scalars whenever the
 * representation is coloured by that array again, so that switching between an array of
 * display colours and one of values shows both right.
 * Each <Property> sets the named property (numbers separated by spaces, as in
 * default_values); <ColorBy> sets ColorArrayName. A property set by the caller since the
 * representation was created (Show(..., MapScalars=1) in Python) is left alone, and an
 * unknown property name is reported as a warning, not an error.
 */

#ifndef vtkMovingLightRadiosityRepresentationDefaults_h
#define vtkMovingLightRadiosityRepresentationDefaults_h

#include "MovingLightRadiosityPluginDisplayModule.h" // For export macro
#include "vtkSMProxyInitializationHelper.h"

class MOVINGLIGHTRADIOSITYPLUGINDISPLAY_EXPORT vtkMovingLightRadiosityRepresentationDefaults
  : public vtkSMProxyInitializationHelper
{
public:
  static vtkMovingLightRadiosityRepresentationDefaults* New();
  vtkTypeMacro(vtkMovingLightRadiosityRepresentationDefaults, vtkSMProxyInitializationHelper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  void PostInitializeProxy(
    vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp) override;

protected:
  vtkMovingLightRadiosityRepresentationDefaults() = default;
  ~vtkMovingLightRadiosityRepresentationDefaults() override = default;

private:
  void AddColorMap(vtkPVXMLElement* element);

  vtkMovingLightRadiosityRepresentationDefaults(
    const vtkMovingLightRadiosityRepresentationDefaults&) = delete;
  void operator=(const vtkMovingLightRadiosityRepresentationDefaults&) = delete;
};

#endif
