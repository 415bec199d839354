/**
 * @class   vtkMovingLightRadiosity
 * @brief   radiosity of a polygonal scene lit by a light that moves along a trajectory
 *
 * vtkMovingLightRadiosity computes the diffuse illumination (radiosity, W/m^2) of a scene for
 * every position of a moving area light, with the reuse of shooting and gathering paths of
 * Sbert & Castro ("Reuse of Paths in Final Gathering Step with Moving Light Sources"): one
 * run solves all the frames, each path serving every light position.
 *
 * Inputs:
 * - port 0, Scene (required): polygons and triangle strips; vertices and lines are ignored
 *   with a warning. Any other data set gives its surface (its polygons and the boundary faces
 *   of its volume cells, with their cell arrays), a composite data set the surfaces of all
 *   its leaves together (a cell array some leaf lacks is dropped, with a warning). The cell array
 * named by ReflectanceArrayName (default `Reflectance`) gives each cell's reflectance (3
 * components, RGB, or 1 component, grey; every value >= 0 and < 1). Without it the scene is grey
 * 0.5 and a warning says so. The cell array named by EmissionArrayName (default `Emission`; 3 or 1
 * components, W/m^2, >= 0) makes those cells static emitters that also reflect: they emit from
 * their front side in every frame. The scene is remeshed into patches of about PatchSize.
 * - port 1, Light (required when LightType is Area and nothing in the Scene emits): one or
 *   more planar polygons emitting diffusely along their normals (right-hand rule); of any
 *   other data set or a composite, its surface, as for the Scene. The
 *   integer cell array `LightId` groups them into several lights (one light without it); the
 *   cell array `LightPower` (3 components, W) gives each light its power, else each gets the
 *   LightPower property. A light's area centroid is its reference point. The Light's polygons
 *   only emit; they are not part of the scene's geometry: no ray stops at them (they shadow
 *   neither this light, nor another, nor light the scene reflects) and they receive no
 *   light. Emitting cells of the Scene are surfaces, and occlude like any other.
 * - port 2, Trajectory (optional): with one light, the points, in order, are the positions
 *   of the light's centroid, one per frame; with several, one polyline per light in LightId
 *   order (a polyline of one point is a light that does not move; moving lights must have one
 *   point per frame). Optional point arrays: `Time` (1 component, increasing: the frame times,
 *   else 0, 1, ..., n-1); `Normal` (3 components: the light's emission direction in that
 *   frame; it is turned about its centroid by the smallest rotation that takes its own mean
 *   normal there); `Orientation` (4 components, quaternion w, x, y, z: the full rotation about
 *   the centroid relative to the light as given, normalised with a warning when not unit; it
 *   wins over `Normal`); `Power` (1 or 3 components: a factor >= 0 on the light's power in
 *   that frame, 0 is off). With LightType Directional the points are the directions towards
 *   the light (the sun), one per frame, of any length but 0; `Power` scales SunIrradiance
 *   (clouds, night); a direction below the horizon (across Up) is night: that frame is dark,
 *   with a warning; `SunAzimuth` and `SunElevation` (degrees), if present, are passed to the
 *   outputs' field data; `DirectNormalIrradiance` (W/m^2) replaces SunIrradiance per frame,
 *   and `SkyDiffuseHorizontal` (W/m^2) and `DayOfYear` (1 to 366, the Perez sky's date) set
 *   the sky per frame. Without this input the light moves in a straight line from
 *   PathStart to PathEnd in NumberOfPositions frames (Directional: the direction does; a
 *   LightMaterial's lamp from where the Scene has it, see PathFromLightMaterial);
 *   with neither a Light nor a LightMaterial, the scene's own emissive surfaces light it in
 *   one frame.
 * - port 3, Sensors (optional): measuring points (any point set, e.g. a work-plane grid at
 *   0.8 m or points on a facade) with the point array `Normals` (3 components, any length
 *   but 0: the direction each sensor's measuring side faces). Sensors receive light but
 *   neither block nor reflect it: the surfaces' radiosity is the same, bit for bit, with and
 *   without them. Missing or zero normals, and NaN points, are refused by name.
 *
 * Outputs:
 * - port 0, Elements: the element mesh (triangles, four per patch) with the cell arrays
 *   `Radiosity` (= `EmittedRadiosity` + `DirectRadiosity` + `IndirectRadiosity`),
 *   `DirectRadiosity`, `IndirectRadiosity`, `EmittedRadiosity` (3 components, W/m^2, of the
 *   element's lit side: the side on which its surface, the patches joined by edges across
 *   which it bends by at most 30 degrees, received more power over the whole animation, so
 *   that a room made of outward-facing polygons still shows its lit walls, and a surface
 *   one side, not each element's noisier choice), `RadiosityFront`
 *   and `RadiosityBack`, `IrradianceFront`, `IrradianceBack`, `IlluminanceFront` and
 *   `IlluminanceBack` (each side's, when TwoSided), `Reflectance` and `PatchId`, and `Color`, the
 *   display colour of `Radiosity` (see Exposure). The Scene's own cell arrays (a zone, a
 *   `MaterialId` with the field data `MaterialNames`) are passed on to the elements and
 *   patches, each taking the values of the Scene cell nearest its centre, since remeshing
 *   merges coplanar cells. For smooth shading its points are split
 *   along creases (lit-side normals more than 30 degrees apart), between materials and
 *   between the lit sides of thin walls, and carry `Radiosity` (area-weighted mean of the
 *   cells around the point), `Color` (its display colour) and `ScenePointId` (the remeshed
 *   scene's point it was split from: below the Patches output's point count, that point of
 *   the Patches; above, the midpoint of a patch edge, which only elements have). Cells and
 *   points also carry `Irradiance` (3 components, W/m^2: the light arriving on the lit
 *   side, direct and indirect, the surface's own emission excluded, so that black surfaces
 *   have it too; at points averaged as `Radiosity`) and `Illuminance` (1 component, lx:
 *   LuminousEfficacy times the luminance of `Irradiance`). With ErrorBatches above 1, cells
 *   and points carry the standard errors `RadiosityStdError` and `IrradianceStdError` (3
 *   components, W/m^2, of `Radiosity` and `Irradiance`) and `IlluminanceStdError` (lx,
 *   LuminousEfficacy times the luminance of `IrradianceStdError`), at points averaged as
 *   `Radiosity`; with TwoSided, cells also carry each side's, `RadiosityStdErrorFront`,
 *   `RadiosityStdErrorBack` and so for the other two. `Color` is the active scalars of
 *   points and cells. Its field data holds the solver statistics (paths, rays by kind,
 *   seconds by phase, patches, elements, frames, reuse modes, predicted speed-up), the frame
 *   shown (`FrameIndex`), where the light is in it (`LightPosition`, its centroid, and
 *   `LightTranslation`, from the Light input), what the area and point lights emit in it
 *   (`LightPower`, RGB W, the Light output's `Power` summed, and `LightLuminousFlux`, lm),
 *   `SolveCount`, the exposure (`AutoExposure`,
 *   `Exposure`, `ExposureScale`) and `LuminousEfficacy`; with an error estimate, one value per
 *   frame of `RelativeErrorMedian`, `RelativeErrorP95` and `LitElements` (the relative error
 *   over the lit elements, see ErrorBatches), `ErrorBatches` (batches run), `ErrorRounds`,
 *   `TargetRelativeError` and the string `StoppedBy` ("batches", "target", "time limit" or
 *   "path limit"). Every output's field data states
 *   the units: `PowerUnits` "W", `RadiosityUnits` and `IrradianceUnits` "W/(scene unit)^2"
 *   (W/m^2 for a scene in metres) and `IlluminanceUnits` "lm/(scene unit)^2" (lx for a
 *   scene in metres).
 * - port 1, Patches: the patch mesh with `Radiosity` (the patch-level shooting solution of
 *   the patch's lit side) and `Reflectance`.
 * - port 2, Light: the lights as solved in the frame shown: each area light's polygons where
 *   they are and each point light (LightType Point, or a Luminaire without an opening) as a
 *   vertex at its position, with the cell arrays `Power` (RGB, W: the power emitted in that
 *   frame, LightFluxLumens, the file's flux, the Trajectory's `Power` and TILT factors
 *   applied; an area light's shared between its polygons by area) and `LuminousFlux` (lm:
 *   LuminousEfficacy times the luminance of `Power`).
 * - port 3, Sensors: the sensor points as vertices with `Normals`, `Irradiance` (RGB, W/m^2)
 *   and `Illuminance` (lx, with the efficacy of the element arrays) of the frame shown, and
 *   the daylight metrics over all the time steps (constant over time): `DaylightAutonomy`
 *   (share of steps with at least DaylightAutonomyThreshold), `UDILow` (below 100 lx),
 *   `UDIUseful` (100 to 2000 lx), `UDIHigh` (above 2000 lx) and `DirectSunHours` (hours
 *   whose direct sun alone gives over 1000 lx; a step lasts the Trajectory's field data
 *   `TimeStepHours`, as vtkSunPathSource gives it, else the median spacing of its `Time` in
 *   hours, 1 hour with one step). With
 *   ErrorBatches above 1, `IrradianceStdError` (3 components, W/m^2) and
 *   `IlluminanceStdError` (lx, the efficacy times the luminance of IrradianceStdError): the
 *   sensor's own sampling and the noise of the solution its rays read, from every batch. Its
 *   field data (and every output's, with a Sensors input) adds the rays the sensors cast,
 *   counted exactly: `SensorShadowRays` (towards the lights, per frame where they can reach
 *   the sensor), `SensorGatheringRays` (sensors x SensorRays, for all frames) and
 *   `SecondsSensors`, and with ErrorBatches above 1, per frame, the lit sensors' relative
 *   error `SensorRelativeErrorMedian` and `SensorRelativeErrorP95` and their count
 *   `LitSensors`. Empty without a Sensors input (Documentation/Method.md, "Sensors").
 *
 * Time: the outputs have one time step per light position (TIME_STEPS, TIME_RANGE). The
 * first update solves every frame at once and keeps the result; requests for other times
 * are served from it without solving again, until an input or a property other than
 * Exposure changes. A time between two steps shows the step at or below it. All the outputs
 * show the time requested on the port being updated. The filter's time is not passed
 * upstream: an input with time steps of its own (a file series) is taken at its first time
 * step whatever time is shown, and re-executions of an input for another consumer's time
 * (ParaView's view of the same reader) do not solve again: a solve follows the modification
 * times of the upstream algorithms and of data given with SetInputData, so a source whose
 * output changes without them (a script reading a file it was not told changed) needs
 * Modified() on it or on this filter. The outputs share their unchanging
 * arrays (points, cells, `Reflectance`, ...) with the kept result: edit a DeepCopy of an output,
 * not the output itself, or the other time steps show the edit.
 *
 * Progress is reported through UpdateProgress; setting AbortExecute (or aborting an upstream
 * algorithm, see vtkAlgorithm::CheckAbort) stops the solve within a fraction of a second, with
 * empty outputs and an error, and clears the flag. An aborted update reports no progress after
 * the abort, not even the 1.0 VTK's executive reports at the end of every execution (which
 * ParaView shows as a finished update): the progress goes through the filter's own
 * vtkProgressObserver, and a ProgressEvent past an abort is dropped. Replacing that observer
 * with SetProgressObserver replaces this too. A failed update still ends at 1.0, as in VTK. An
 * aborted or failed solve is not tried again until a property or an input changes (or Modified() is
 * called): a request for another time step or output port meanwhile repeats the error without
 * solving. Bad input (NaN points, a wrong `Reflectance`, a light without polygons, ...) gives an
 * error naming what to fix and empty outputs. An empty scene gives empty outputs and no error.
 * Numeric properties are kept as given, not clamped: a value outside the range its description
 * gives (NaN included) fails the update with an error naming the property, the value and what to
 * give.
 *
 * Several MPI ranks (pvbatch --symmetric or pvserver under mpiexec; the global controller
 * has more than one process): every rank gathers the whole Scene, Light and Trajectory from
 * the pieces that arrive, in a canonical cell order (global or vtkOriginalCellIds, else rank
 * then cell order), traces its share of the paths and gathering rays, and holds the serial
 * solution bit for bit once the sums over ranks are done; each rank outputs the elements and
 * patches whose nearest input cell is its own, rank 0 the Light. An abort or an error on any
 * rank is reported on every rank, and leaves every rank in the same state, so that the next
 * request solves on every rank or on none. A rank that comes to a solve alone names the ranks
 * it waits for after 10 s; with the environment variable MLR_RANK_WAIT_LIMIT (seconds) it
 * then aborts the MPI job with that error rather than wait for ever. See README, "Running on
 * a cluster".
 *
 * @warning
 * The solve uses NumberOfThreads threads of its own (0: every core), whatever the
 * vtkSMPTools backend.
 *
 * @sa
 * The method is derived in Documentation/Method.md of the MovingLightRadiosity project.
 */

#ifndef vtkMovingLightRadiosity_h
#define vtkMovingLightRadiosity_h

#include "MovingLightRadiosityFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <cstddef>    // For std::size_t
#include <functional> // For std::function
#include <memory>     // For std::unique_ptr
#include <string>     // For std::string

class MOVINGLIGHTRADIOSITYFILTERS_EXPORT vtkMovingLightRadiosity : public vtkPolyDataAlgorithm
{
public:
  static vtkMovingLightRadiosity* New();
  vtkTypeMacro(vtkMovingLightRadiosity, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The input ports, in order.
  enum InputPorts
  {
    SCENE_PORT = 0,
    LIGHT_PORT = 1,
    TRAJECTORY_PORT = 2,
    SENSORS_PORT = 3
  };

  /// The output ports, in order.
  enum OutputPorts
  {
    ELEMENTS_PORT = 0,
    PATCHES_PORT = 1,
    LIGHT_OUTPUT_PORT = 2,
    SENSORS_OUTPUT_PORT = 3
  };

  ///@{
  /**
   * Connect the scene (port 0), the light (port 1) and the optional trajectory (port 2).
   */
  void SetSceneConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(0, output); }
  void SetLightConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetTrajectoryConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(2, output); }
  void SetSceneData(vtkDataObject* data) { this->SetInputData(0, data); }
  void SetLightData(vtkDataObject* data) { this->SetInputData(1, data); }
  void SetTrajectoryData(vtkDataObject* data) { this->SetInputData(2, data); }
  void SetSensorsConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(3, output); }
  void SetSensorsData(vtkDataObject* data) { this->SetInputData(3, data); }
  ///@}

  ///@{
  /**
   * Total power of the light, per channel (RGB, W). Default 100, 100, 100.
   */
  vtkSetVector3Macro(LightPower, double);
  vtkGetVector3Macro(LightPower, double);
  ///@}

  ///@{
  /**
   * Effective shooting paths per frame, N, from 1 to 10^11. Default 600000.
   */
  vtkSetMacro(NumberOfPaths, vtkIdType);
  vtkGetMacro(NumberOfPaths, vtkIdType);
  ///@}

  ///@{
  /**
   * Gathering rays per frame as a multiple k of NumberOfPaths; 0 skips final gathering and
   * the elements show their patch's shooting solution. At most 1000. Default 1.
   */
  vtkSetMacro(GatheringRatio, double);
  vtkGetMacro(GatheringRatio, double);
  ///@}

  ///@{
  /**
   * Probability lambda that a shooting path continues after its first hit, from 0.001 to 1.
   * Default 0.25.
   */
  vtkSetMacro(FirstBounceSurvival, double);
  vtkGetMacro(FirstBounceSurvival, double);
  ///@}

  ///@{
  /**
   * Reuse every shooting path for all light positions (else each frame shoots its own).
   * Default on.
   */
  vtkSetMacro(ReuseShooting, vtkTypeBool);
  vtkGetMacro(ReuseShooting, vtkTypeBool);
  vtkBooleanMacro(ReuseShooting, vtkTypeBool);
  ///@}

  ///@{
  /**
   * With ReuseShooting, share the paths unequally over the light's positions so that every
   * frame is sampled as well as the others: a pilot of reused paths finds the frames the
   * mixture covers worst (the ends of a trajectory) and gives their positions more paths.
   * Unbiased either way. Default on; off casts the same number from every position.
   */
  vtkSetMacro(BalanceFrames, vtkTypeBool);
  vtkGetMacro(BalanceFrames, vtkTypeBool);
  vtkBooleanMacro(BalanceFrames, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Reuse one set of gathering rays for all frames (else each frame gathers its own).
   * Default on.
   */
  vtkSetMacro(ReuseGathering, vtkTypeBool);
  vtkGetMacro(ReuseGathering, vtkTypeBool);
  vtkBooleanMacro(ReuseGathering, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Target patch edge length, in scene units, 0 or more; 0 picks one that gives about 3000
   * patches. Default 0.
   */
  vtkSetMacro(PatchSize, double);
  vtkGetMacro(PatchSize, double);
  ///@}

  ///@{
  /**
   * Seed of the random numbers, 0 or positive: the same seed gives the same result. Default 0.
   */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /**
   * Threads of the solve, up to 1024; 0 uses every core. The result does not depend on it,
   * so changing it keeps a solve already made (not with a TimeLimit, whose rounds depend on
   * the speed, nor with CachedChunks, whose chunks are solved again when shown). Default 0.
   */
  void SetNumberOfThreads(int threads);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /**
   * Surfaces scatter light on both sides (else back faces absorb all). Default on.
   */
  vtkSetMacro(TwoSided, vtkTypeBool);
  vtkGetMacro(TwoSided, vtkTypeBool);
  vtkBooleanMacro(TwoSided, vtkTypeBool);
  ///@}

  ///@{
  /**
   * First light centroid position when no Trajectory is connected. Not used for a
   * LightMaterial with PathFromLightMaterial on: that lamp starts where the Scene has it.
   * With a Trajectory connected a change keeps the solve. Default 0, 0, 0.
   */
  void SetPathStart(double x, double y, double z);
  void SetPathStart(const double start[3]);
  vtkGetVector3Macro(PathStart, double);
  ///@}

  ///@{
  /**
   * Last light centroid position when no Trajectory is connected; with one a change keeps the
   * solve. Default 1, 0, 0.
   */
  void SetPathEnd(double x, double y, double z);
  void SetPathEnd(const double end[3]);
  vtkGetVector3Macro(PathEnd, double);
  ///@}

  ///@{
  /**
   * Light positions (frames) from PathStart to PathEnd when no Trajectory is connected
   * (one frame when there is no light at all, only emissive scene surfaces), from 1 to 100000;
   * with a Trajectory connected a change keeps the solve. Default 10.
   */
  void SetNumberOfPositions(int positions);
  vtkGetMacro(NumberOfPositions, int);
  ///@}

  /// The kinds of light (LightType).
  enum LightTypes
  {
    AREA_LIGHT = 0,
    DIRECTIONAL_LIGHT = 1,
    POINT_LIGHT = 2,
    LUMINAIRE_LIGHT = 3
  };

  ///@{
  /**
   * Area: the Light input's polygons, moved along the Trajectory. Directional: a light at
   * infinity (the sun) whose direction in each frame is a Trajectory point; the Light input is
   * not needed and SunIrradiance replaces LightPower. Point: one point light at the
   * Trajectory's points (or from PathStart to PathEnd) of power LightPower, emitting with the
   * light distribution (see LightDistributionFile) about its nadir, -z unless a Normal or
   * Orientation turns it; the Light input is not needed. Luminaire: the LightDistributionFile's
   * luminaire as an area light of its luminous opening (a rectangle, or a polygon of an
   * ellipse's or a circle's area: the opening seen from below), centred on the Trajectory's
   * points and posed as the point light is (nadir -z, C = 0 along +x); a file that gives no
   * opening makes it a point light, with a warning. Default Area. Kept as given: another
   * value fails the update with an error naming LightType.
   */
  vtkSetMacro(LightType, int);
  vtkGetMacro(LightType, int);
  void SetLightTypeToArea() { this->SetLightType(AREA_LIGHT); }
  void SetLightTypeToDirectional() { this->SetLightType(DIRECTIONAL_LIGHT); }
  void SetLightTypeToPoint() { this->SetLightType(POINT_LIGHT); }
  void SetLightTypeToLuminaire() { this->SetLightType(LUMINAIRE_LIGHT); }
  ///@}

  ///@{
  /**
   * Irradiance of the directional light on a surface facing it, W/m^2 (before the
   * Trajectory's Power factor). A Trajectory with the point array DirectNormalIrradiance (a
   * weather file's, from vtkSunPathSource) gives it per frame instead, and SunIrradiance 0
   * still turns the direct sun off; 0 or more. Other light types keep the solve when it
   * changes. Default 1000 (the sun at noon on a clear day).
   */
  void SetSunIrradiance(double irradiance);
  vtkGetMacro(SunIrradiance, double);
  ///@}

  /// The sky models (SkyModel).
  enum SkyModels
  {
    NO_SKY = 0,
    UNIFORM_SKY = 1,
    CIE_OVERCAST_SKY = 2,
    CIE_CLEAR_SKY = 3,
    PEREZ_SKY = 4
  };

  ///@{
  /**
   * A sky, alone or with the sun (LightType Directional): none, uniform, CIE overcast, CIE
   * clear (type 12) or Perez all-weather; with a lamp (a Light, a LightMaterial or a point
   * light) it is an error, since one frame's Illuminance takes one efficacy, the daylight's. The
   * clear and Perez skies need LightType Directional: they follow its sun in every frame
   * (SunIrradiance 0 keeps the sun's frames with no direct sun). Each sky is scaled so that an
   * unobstructed horizontal surface receives SkyDiffuseHorizontal, or the Trajectory's point array
   * SkyDiffuseHorizontal per frame; the Perez sky also reads the direct normal irradiance, the
   * array DirectNormalIrradiance or else the sun's irradiance (SunIrradiance times Power). Nothing
   * lights from below the horizon. With a sky the Illuminance arrays use the Perez luminous
   * efficacy of each frame's daylight (field data LuminousEfficacy and LuminousEfficacyModel).
   * Default none.
   */
  vtkSetMacro(SkyModel, int);
  vtkGetMacro(SkyModel, int);
  ///@}

  ///@{
  /// The sky's diffuse horizontal irradiance E_dh, W/m^2, when the Trajectory has no
  /// SkyDiffuseHorizontal array; 0 or more. A daylight sky's: in a frame whose sun (LightType
  /// Directional) is below the horizon the sky is dark, where a Trajectory's per-frame value
  /// (a weather file's, twilight included) is used as given. Default 100.
  vtkSetMacro(SkyDiffuseHorizontal, double);
  vtkGetMacro(SkyDiffuseHorizontal, double);
  ///@}

  ///@{
  /// The zenith of the sky, the vertical a LightDistributionFile's TILT=INCLUDE table
  /// measures each pose's tilt from, and with LightType Directional the horizon below which a
  /// sun is night when the Trajectory gives no SunElevation (with one, the elevation decides
  /// and a disagreement with Up is warned of); any length but 0. Default 0, 0, 1.
  vtkSetVector3Macro(Up, double);
  vtkGetVector3Macro(Up, double);
  ///@}

  ///@{
  /**
   * Aim every light at AimPoint in every frame: an area light's emission direction is turned
   * to point from its centroid to AimPoint, a point light's nadir from its position (a
   * Trajectory's Orientation still wins). Default off.
   */
  vtkSetMacro(AimAtPoint, vtkTypeBool);
  vtkGetMacro(AimAtPoint, vtkTypeBool);
  vtkBooleanMacro(AimAtPoint, vtkTypeBool);
  ///@}

  ///@{
  /**
   * The point lights face when AimAtPoint is on, in scene units. Default 0, 0, 0.
   */
  vtkSetVector3Macro(AimPoint, double);
  vtkGetVector3Macro(AimPoint, double);
  ///@}

  // ---------------------------------------------------------------- Luminaires
  ///@{
  /**
   * A photometric file (IES LM-63 .ies or EULUMDAT .ldt) whose luminous intensity
   * distribution every area and point light emits with, in the light's photometric frame:
   * the nadir (gamma 0) is an area light's emission normal (its first polygon's) or a point
   * light's -z, C = 0 is along an area light's first edge or a point light's +x; the frame
   * turns with the light. The power is LightFluxLumens, LightPower or, with
   * LightFluxFromFile, the file's own flux. An IES file's TILT=INCLUDE table multiplies each
   * pose's power by its factor at that pose's tilt from straight down (-Up). An area light
   * whose extent differs from the file's luminous opening by more than a quarter is warned
   * of (LightType Luminaire emits from the opening itself). Default "" (diffuse, Lambertian,
   * emitters).
   */
  vtkSetStdStringFromCharMacro(LightDistributionFile);
  vtkGetCharFromStdStringMacro(LightDistributionFile);
  ///@}

  ///@{
  /**
   * A spot: uniform intensity within SpotHalfAngle (degrees, up to 180) of the nadir,
   * falling linearly to zero over SpotSoftEdge degrees beyond it. A half angle of 0 is no
   * spot; a spot and a LightDistributionFile exclude each other. Defaults 0 and 0.
   */
  vtkSetMacro(SpotHalfAngle, double);
  vtkGetMacro(SpotHalfAngle, double);
  vtkSetMacro(SpotSoftEdge, double);
  vtkGetMacro(SpotSoftEdge, double);
  ///@}

  ///@{
  /**
   * A luminaire's luminous flux (lm), for every area and point light, instead of LightPower:
   * the power is LightFluxLumens / LuminousEfficacy watts of luminance, with the light's
   * colour (LightPower, or the Light's LightPower cell array) as the RGB ratio, scaled so
   * that 0.2126 R + 0.7152 G + 0.0722 B of it equals that. 0 keeps LightPower; no negative
   * flux. Default 0.
   */
  vtkSetMacro(LightFluxLumens, double);
  vtkGetMacro(LightFluxLumens, double);
  ///@}

  ///@{
  /**
   * When LightFluxLumens is 0 and a LightDistributionFile is given, every area and point
   * light emits the file's own luminous flux (the integral of its candela table, times the
   * candela multiplier and ballast factor) instead of LightPower's watts, LightPower keeping
   * only its colour, as with LightFluxLumens. Off keeps LightPower's watts. Default off.
   */
  vtkSetMacro(LightFluxFromFile, bool);
  vtkGetMacro(LightFluxFromFile, bool);
  vtkBooleanMacro(LightFluxFromFile, bool);
  ///@}
  // --------------------------------------------------------- end of Luminaires block

  ///@{
  /**
   * Names of the Scene's cell arrays of reflectance and emission. Defaults "Reflectance" and
   * "Emission".
   */
  vtkSetStdStringFromCharMacro(ReflectanceArrayName);
  vtkGetCharFromStdStringMacro(ReflectanceArrayName);
  vtkSetStdStringFromCharMacro(EmissionArrayName);
  vtkGetCharFromStdStringMacro(EmissionArrayName);
  ///@}

  ///@{
  /**
   * The name of a Scene material (field data `MaterialNames`, cell array `MaterialId`, as
   * vtkRadiositySceneReader gives them) whose polygons are taken out of the scene to become
   * the light that moves along the Trajectory; the Light input is then not used. Other
   * emissive materials stay in the scene as static emitters. Default "" (the Light input).
   */
  vtkSetStdStringFromCharMacro(LightMaterial);
  vtkGetCharFromStdStringMacro(LightMaterial);
  ///@}

  ///@{
  /**
   * With LightMaterial and no Trajectory: the first position is the lamp where the Scene has
   * it (the area centroid of the material's polygons), so that the first time step shows the
   * scene as modelled, and the straight path moves it from there to PathEnd in
   * NumberOfPositions frames; PathStart is not used. Off: from PathStart to PathEnd, as for a
   * Light input, whose polygons are a shape the path places. A Trajectory places the lamp
   * either way. Default off, so that a script's PathStart keeps its meaning; on in the
   * ParaView plugin, where PathStart's default comes from the Scene's bounds, not the lamp.
   */
  vtkSetMacro(PathFromLightMaterial, vtkTypeBool);
  vtkGetMacro(PathFromLightMaterial, vtkTypeBool);
  vtkBooleanMacro(PathFromLightMaterial, vtkTypeBool);
  ///@}

  ///@{
  /**
   * With LightMaterial: take the light's power from the material's emission (Emission times
   * area, pi Ke area for an OBJ material with Ke) when it emits; off, or for a material that
   * does not emit, LightPower. Default on.
   */
  vtkSetMacro(LightPowerFromMaterial, vtkTypeBool);
  vtkGetMacro(LightPowerFromMaterial, vtkTypeBool);
  vtkBooleanMacro(LightPowerFromMaterial, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Refuse work estimated to need more memory than this (MiB), before allocating it: taking
   * the scene for remeshing, remeshing it, and the solve with its outputs (a solve that
   * cannot fit is refused before remeshing runs, from the patch count expected); 0 means
   * half of the physical memory; no negative limit. Default 0.
   */
  vtkSetMacro(MemoryLimit, int);
  vtkGetMacro(MemoryLimit, int);
  ///@}

  ///@{
  /**
   * Solve the light positions in chunks of this many consecutive frames, each a full-reuse
   * solve of its own blended with the next over ChunkOverlap positions on each side of a
   * seam, so that the solve's memory depends on the chunk, not on the animation's length;
   * 0 lets MemoryLimit choose: every frame at once when that fits, else the longest chunks
   * that do. 1 is refused (the blends of a chunk's two seams would overlap). The frames are
   * kept for the time steps; every chunk solves with Seed, a position casting the same paths
   * in every chunk that solves it. On several MPI ranks with at least as many chunks as ranks
   * (and no Sensors), each rank solves whole chunks and keeps their frames: the rank holding a
   * time step outputs it whole, the others an empty piece. No negative count. Default 0.
   */
  vtkSetMacro(FramesPerChunk, int);
  vtkGetMacro(FramesPerChunk, int);
  ///@}

  ///@{
  /**
   * With chunks (FramesPerChunk or MemoryLimit), the positions m each chunk solves beyond its
   * own frames on each side: each seam blends the two chunks' estimates over those 2m frames,
   * in steps of 1/(2m). The flicker at a seam falls as 1/m; each chunk solves C + 2m
   * positions, so its rays grow as (C + 2m)/C (in chunks of 30, m = 15 took 1.24 times the
   * CPU time of m = 3, part of a chunk's time not growing with its positions).
   * Measured in the paper room over 300 frames in chunks of 30: the flicker of the whole
   * series was 2.4, 1.7 and 1.25 times one unchunked solve's at m = 3 (the default), 7 and 15.
   * 0 takes C/8 (at least 1). At most FramesPerChunk/2, so that a chunk's two seams do not
   * overlap (with chunks MemoryLimit chooses, a larger m is cut to half of them; the field
   * data `ChunkOverlap` gives the m used). No negative count. Default 0.
   */
  vtkSetMacro(ChunkOverlap, int);
  vtkGetMacro(ChunkOverlap, int);
  ///@}

  ///@{
  /**
   * With a solve in several chunks, keep the frames of at most this many chunks, the last
   * ones asked for, rather than every frame: a time step outside them solves its chunk
   * again, with the chunk before it for the blend at its seam (about twice one chunk's
   * solve), the same bits as the first solve; the field data `ChunksSolvedAgain` counts
   * them. The memory limit counts the chunks kept. The display's exposure and lit sides are
   * then those of the first chunk, as when streaming. 0 keeps every frame. One process only:
   * on several MPI ranks, and with Sensors, every frame is kept. No negative count. Default 0.
   */
  vtkSetMacro(CachedChunks, int);
  vtkGetMacro(CachedChunks, int);
  ///@}

  // ---------------------------------------------------------------- Error estimate
  ///@{
  /**
   * The solve runs as this many independent batches of NumberOfPaths / ErrorBatches paths
   * per frame (and as many gathering rays), the result is their mean, and the spread of the
   * batch means gives every element's standard error: the arrays `RadiosityStdError` and the
   * field data `RelativeErrorMedian` and `RelativeErrorP95` (Documentation/Method.md, section
   * 17). 1 is one solve without an error estimate (and none of those arrays). From 1 to 4096,
   * at most NumberOfPaths; other values make the update fail with an error naming
   * ErrorBatches. Default 16.
   */
  vtkSetMacro(ErrorBatches, int);
  vtkGetMacro(ErrorBatches, int);
  ///@}

  ///@{
  /**
   * A target accuracy: above 0, the solve adds rounds of batches (of NumberOfPaths /
   * ErrorBatches paths per frame each) until, in every frame, the 95th percentile of the lit
   * elements' relative error is at most this (0.02 is 2%), or TimeLimit stops it (field data
   * `StoppedBy`, and a warning when the target was not reached). The result stays
   * reproducible for a seed and thread count-independent, unless TimeLimit stops it. Needs
   * ErrorBatches of 2 or more. 0 (off) or from 0.0001 to below 1 (the batches' relative error is
   * at most 1, so a larger target is met at once); negative values and NaN make the update
   * fail with an error naming TargetRelativeError. Default 0.
   */
  vtkSetMacro(TargetRelativeError, double);
  vtkGetMacro(TargetRelativeError, double);
  ///@}

  ///@{
  /**
   * With TargetRelativeError: start no more batches once the batches have taken this many
   * seconds (the first round always completes); the round count then depends on the
   * machine's speed, and the result is no longer reproducible. 0 is no limit. Negative values,
   * NaN and infinity make the update fail with an error naming TimeLimit. Default 0.
   */
  vtkSetMacro(TimeLimit, double);
  vtkGetMacro(TimeLimit, double);
  ///@}
  // -------------------------------------------------------- end of Error estimate block

  // ---------------------------------------------------------------- Display
  ///@{
  /**
   * Exposure of the display colours, in EV (stops), on top of the automatic exposure: the
   * `Color` arrays show Radiosity x 2^(AutoExposure + Exposure), tone mapped with the ACES
   * filmic curve (Narkowicz's fit) and sRGB-encoded. AutoExposure is computed once per solve
   * over every frame and element (it maps the 99th percentile of the lit-side luminance to
   * 1, which the tone map shows as a bright grey, 80%), so that all frames share one
   * exposure. +1 doubles the value before
   * the tone map. Changing it only recolours: it never solves again. From -20 to 20;
   * default 0.
   */
  void SetExposure(double exposure);
  vtkGetMacro(Exposure, double);
  ///@}

  ///@{
  /**
   * Luminous efficacy K of the light, lm/W: the `Illuminance` arrays (lx) are K times the
   * luminance (0.2126 R + 0.7152 G + 0.0722 B) of `Irradiance` (W/m^2). It must be > 0 and
   * at most 683 (the efficacy of monochromatic 555 nm light); other values, NaN included, are
   * kept as given and make the update fail with an error naming LuminousEfficacy. Daylight
   * is not white light: with a sky, or LightType Directional (the sun) alone, the arrays use
   * Perez's efficacy of each frame's daylight instead (field data `LuminousEfficacy` and
   * `LuminousEfficacyModel`). Default 179 (Radiance's value for white light). Changing it
   * keeps the solve (the arrays and the sensors' metrics are computed again from it) unless
   * it converts a light's lumens into watts (LightFluxLumens, or LightFluxFromFile with a
   * LightDistributionFile).
   */
  void SetLuminousEfficacy(double efficacy);
  vtkGetMacro(LuminousEfficacy, double);
  ///@}
  // --------------------------------------------------------------- end of Display block

  ///@{
  /**
   * The illuminance (lx) a sensor's DaylightAutonomy counts the time steps at or above.
   * Changing it only recomputes the metrics from the cached solve: it never solves again.
   * From 0; default 300.
   */
  void SetDaylightAutonomyThreshold(double threshold);
  vtkGetMacro(DaylightAutonomyThreshold, double);
  ///@}

  ///@{
  /**
   * Cosine-distributed rays each sensor casts over its hemisphere, once for all frames: the
   * sky through those that escape, the surfaces' radiosity through those that hit; and an
   * eighth as many points (at least 1) each sensor samples on every area light, each with a
   * shadow ray per frame. Their noise falls as one over the square root or faster. From 16
   * to 1000000; without Sensors a change keeps the solve. Default 512.
   */
  void SetSensorRays(int rays);
  vtkGetMacro(SensorRays, int);
  ///@}

  /**
   * The range of the numeric property `name` ("NumberOfPaths", "Seed", "Exposure", ...) that an
   * update accepts, bounds included, into `range`; false, leaving `range` as it is, for a name
   * without one. The properties keep what they are given: a value outside fails the update
   * with an error naming the property.
   */
  static bool GetPropertyRange(const char* name, double range[2]);

  /**
   * Number of solves performed so far by this filter (new times do not solve again).
   */
  vtkGetMacro(SolveCount, vtkIdType);

  /**
   * Asks the solve under way (or the next one) to stop. Unlike vtkAlgorithm's setter this does
   * not change the MTime: the flag decides no result, and on several ranks a rank whose
   * MTime alone moved would solve again alone, waiting forever for the others.
   */
  void SetAbortExecute(vtkTypeBool abort) override;

#ifndef __VTK_WRAP__
  /**
   * C++ only: streams a solve in several chunks (FramesPerChunk, or chunks the MemoryLimit
   * chooses, with one chunk's frames counted instead of all). Once a chunk's frames are final,
   * `observer` gets each of them in order, as the Elements output of that time step would be,
   * and they are freed after: only the last chunk's frames stay for the time steps. The
   * display's exposure and the lit sides are then those of the first chunk. A solve in one
   * chunk or with sensors keeps every frame as without an observer. Over several ranks that
   * take whole chunks, each rank's observer gets the frames of the chunks it solved (the
   * first chunk's exposure and lit sides on every rank); with fewer chunks than ranks every
   * rank keeps every frame, as without an observer. An empty observer turns streaming off.
   */
  using ChunkObserver = std::function<void(std::size_t frame, vtkPolyData* elements)>;
  void SetChunkObserver(ChunkObserver observer);
#endif

protected:
  vtkMovingLightRadiosity();
  ~vtkMovingLightRadiosity() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestUpdateExtent(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  double LightPower[3];
  vtkIdType NumberOfPaths;
  double GatheringRatio;
  double FirstBounceSurvival;
  vtkTypeBool ReuseShooting;
  vtkTypeBool BalanceFrames;
  vtkTypeBool ReuseGathering;
  double PatchSize;
  int Seed;
  int NumberOfThreads;
  vtkTypeBool TwoSided;
  double PathStart[3];
  double PathEnd[3];
  int NumberOfPositions;
  int MemoryLimit;
  int FramesPerChunk;
  int ChunkOverlap;
  int CachedChunks;
  int LightType;
  double SunIrradiance;
  int SkyModel;
  double SkyDiffuseHorizontal;
  double Up[3];
  vtkTypeBool AimAtPoint;
  double AimPoint[3];
  std::string LightDistributionFile;
  double SpotHalfAngle;
  double SpotSoftEdge;
  double LightFluxLumens;
  bool LightFluxFromFile;
  std::string ReflectanceArrayName;
  std::string EmissionArrayName;
  std::string LightMaterial;
  vtkTypeBool PathFromLightMaterial;
  vtkTypeBool LightPowerFromMaterial;
  int ErrorBatches;
  double TargetRelativeError;
  double TimeLimit;
  vtkIdType SolveCount;
  double Exposure;
  double LuminousEfficacy;
  double DaylightAutonomyThreshold;
  int SensorRays;

private:
  vtkMovingLightRadiosity(const vtkMovingLightRadiosity&) = delete;
  void operator=(const vtkMovingLightRadiosity&) = delete;

  /// Sets a property that does not change the solve (Exposure, the autonomy threshold, the
  /// threads): a kept solve still serves the outputs.
  template <typename T>
  void SetKeepingTheSolve(T& property, T value);
  /// Sets a property that the solve does not use as the inputs and the other properties stand
  /// (`unused`) keeping the solve, else as any other.
  template <typename T>
  void SetUnlessUsed(T& property, T value, bool unused);
  void SetPathPoint(double* point, double x, double y, double z);
  /// Solves every frame and caches the result; returns false (after an error) on failure.
  bool Solve(vtkInformationVector** inputVector);
  /// Fills output port `port` with frame `frame` of the cache; false (after an error) when
  /// that frame is not kept.
  bool FillOutput(int port, std::size_t frame, vtkPolyData* output);

  /// Every UpdateProgress ends here (the filter's vtkProgressObserver): a ProgressEvent,
  /// unless this update was aborted.
  void ReportProgress(double amount);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
  std::function<void(std::size_t, vtkPolyData*)> ChunkFramesObserver;
  /// This update was aborted: nothing more is reported until the next one starts.
  bool ProgressStopped = false;
  /// The time step this update asks for (NaN: none), whose chunk a CachedChunks solve keeps.
  double RequestedTime = 0;
};

#endif
