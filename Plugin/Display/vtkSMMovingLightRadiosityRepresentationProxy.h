/**
 * @class   vtkSMMovingLightRadiosityRepresentationProxy
 * @brief   a representation whose log-scale colour maps get a positive range
 *
 * ParaView 5.11 rescales a lookup table to the finite range of the data it colours. On a log
 * scale a range that reaches 0 cannot be used: vtkSMTransferFunctionProxy then raises its
 * minimum itself and prints "Ranges not valid for log-space. Changed the range to (...)".
 * Illuminance is 0 lx wherever no light arrives (a shadow, a surface facing away, every
 * element of a night frame), so colouring by it on its log scale printed that warning at every
 * rescale of such a frame: Color By, Rescale to Data Range (or over all time steps), and each
 * Apply in the GUI, which grows the lookup tables to the new data.
 *
 * This representation (the XML's MovingLightRadiosityRepresentationProxy) hands a lookup table
 * on a log scale the range it can show of the colour array, in place of the finite range it
 * reads from the array's information:
 * - a minimum of 0 or less raised to 1e-4 of the maximum, but at most 1 (PositiveRangeForLog):
 *   the range ParaView gives after its warning, so that the colours are the same and only the
 *   warning is gone;
 * - no range when nothing is above 0 (a night frame): the lookup table keeps its range, where
 *   ParaView set about 1e-42 to 1e-38;
 * - the data's own when its minimum is above 0.
 * Only the finite range of the component the lookup table maps changes, and only while it is on
 * a log scale: the array's range, name, type, components and counts stay the data's, and linear
 * lookup tables are ParaView's as before.
 */

#ifndef vtkSMMovingLightRadiosityRepresentationProxy_h
#define vtkSMMovingLightRadiosityRepresentationProxy_h

#include "MovingLightRadiosityPluginDisplayModule.h" // For export macro
#include "vtkNew.h"                                  // For vtkNew
#include "vtkSMPVRepresentationProxy.h"

class MOVINGLIGHTRADIOSITYPLUGINDISPLAY_EXPORT vtkSMMovingLightRadiosityRepresentationProxy
  : public vtkSMPVRepresentationProxy
{
public:
  static vtkSMMovingLightRadiosityRepresentationProxy* New();
  vtkTypeMacro(vtkSMMovingLightRadiosityRepresentationProxy, vtkSMPVRepresentationProxy);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The colour array's information, with the finite range a log-scale lookup table can show
   * (see the class documentation). ParaView's lookup tables read the range they grow to on
   * Apply here (vtkSMTransferFunctionProxy::ComputeDataRange).
   */
  vtkPVArrayInformation* GetArrayInformationForColorArray(
    bool checkRepresentedData = true) override;

  /**
   * The range a log-scale lookup table gets for data whose finite range is `range`, into
   * `range`: unchanged when its minimum is above 0, the minimum raised to min(1e-4 x maximum,
   * 1) when only the maximum is, and false (`range` unchanged) when nothing is above 0.
   */
  static bool PositiveRangeForLog(double range[2]);

protected:
  vtkSMMovingLightRadiosityRepresentationProxy();
  ~vtkSMMovingLightRadiosityRepresentationProxy() override;

  /**
   * Rescale to the data given (Color By and Rescale to Data Range pass the array of the
   * current time, Rescale over All Timesteps that of every time step) through
   * ForLogScale.
   */
  bool RescaleTransferFunctionToDataRange(
    vtkPVArrayInformation* info, bool extend = false, bool force = true) override;

private:
  /**
   * `info` as the lookup table sees it: `info` itself, unless the lookup table is on a log scale
   * and the finite range of the component it maps reaches 0 or below; then a copy in
   * LogScaleInformation whose finite range there is PositiveRangeForLog's (an empty range when
   * nothing is above 0).
   */
  vtkPVArrayInformation* ForLogScale(vtkPVArrayInformation* info);

  /// One copy per proxy: a later call rewrites what an earlier caller was given, which
  /// ParaView reads at once.
  vtkNew<vtkPVArrayInformation> LogScaleInformation;

  vtkSMMovingLightRadiosityRepresentationProxy(
    const vtkSMMovingLightRadiosityRepresentationProxy&) = delete;
  void operator=(const vtkSMMovingLightRadiosityRepresentationProxy&) = delete;
};

#endif
