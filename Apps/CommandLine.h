// The options of moving-light-radiosity: parsing, checking and the help text.
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>

class vtkMovingLightRadiosity;

namespace mlr::cli
{

/// A bad command line: the message says which option and what to give instead.
class UsageError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

using Triple = std::array<double, 3>;

/// --sun-path LAT,LON,YYYY-MM-DD,HH:MM,HH:MM,MINUTES as given (checked by Core's sunPath).
struct SunPathSpec
{
  double latitude = 0, longitude = 0;
  int year = 0, month = 0, day = 0;
  double startHour = 0, endHour = 0; ///< local clock time, hours
  double stepMinutes = 0;
};

/// What the command line asked for. Unset optionals keep the filter's defaults.
struct Options
{
  bool help = false;
  /// True when no argument was given: the embedded Cornell box with pictures.
  bool defaultRun = false;

  std::string scene; ///< empty: the embedded Cornell box (with its light and trajectory)
  std::string light;
  std::string trajectory;
  std::optional<Triple> from, to;
  std::optional<long long> frames;

  std::optional<Triple> aim; ///< every frame, the light faces this point
  /// The scene's material whose polygons become the light, instead of --light.
  std::optional<std::string> lightMaterial;

  /// The sun (a directional light) instead of --light: directions from a file, or computed.
  std::string sunDirections;
  std::optional<SunPathSpec> sunPath;
  std::optional<double> sunIrradiance;        ///< W/m^2
  std::optional<double> timeZone;             ///< hours from UTC of the clock times of --sun-path
  std::optional<Triple> north, up;            ///< the scene's north and zenith (--sun-path, --sky)
  std::optional<std::string> sky;             ///< uniform, cie-overcast, cie-clear or perez
  std::optional<double> skyDiffuseHorizontal; ///< W/m^2
  /// A weather file's hours as frames (sun and Perez sky): --weather, --dates, --hours, --night.
  std::string weather;                     ///< FILE.epw
  std::optional<std::array<int, 4>> dates; ///< first month, day, last month, day
  std::optional<std::array<int, 2>> hours; ///< first and last clock hour, 0 to 23
  bool night = false;

  std::optional<Triple> lightPower;

  /// Luminaires: a point light instead of polygons, and the intensity distribution and flux
  /// of every light.
  bool pointLight = false;
  bool luminaire = false; ///< an area light of the file's luminous opening
  /// Reused paths shared equally over the positions (no balancing of the frames).
  bool equalShares = false;
  std::string lightDistribution;             ///< FILE.ies or FILE.ldt
  std::optional<std::array<double, 2>> spot; ///< half angle and soft edge, degrees
  std::optional<double> lightLumens;         ///< lm
  std::optional<long long> paths;
  std::optional<double> gatherRatio;
  std::optional<double> survival;
  std::optional<std::string> reuse; ///< none, gathering, shooting or both
  std::optional<double> patchSize;
  std::optional<long long> seed;
  std::optional<long long> threads;
  std::optional<long long> memoryLimit; ///< MiB
  std::optional<long long> framesPerChunk;
  std::optional<long long> chunkOverlap;
  std::optional<long long> errorBatches;
  std::optional<double> targetError; ///< a fraction: 0.02 is 2%
  std::optional<double> timeLimit;   ///< seconds, with targetError

  std::optional<double> luminousEfficacy; ///< lm/W, for the Illuminance arrays

  /// Sensors: points with Normals from a file, or a work-plane grid (height, spacing) over
  /// every upward-facing floor; and the daylight autonomy threshold (lx).
  std::string sensors;
  std::optional<std::array<double, 2>> workPlane;
  std::optional<double> daThreshold;
  /// Hemisphere rays per sensor (the filter's SensorRays).
  std::optional<long long> sensorRays;
  bool usesSensors() const { return !this->sensors.empty() || this->workPlane.has_value(); }

  std::string output; ///< PATH.pvd
  std::string stats;  ///< FILE.json, or empty
  std::string png;    ///< DIR, or empty for no pictures

  bool usesEmbeddedScene() const { return this->scene.empty(); }
  /// A glTF scene (.gltf, .glb): Y-up, as the glTF standard has it.
  bool sceneIsYUp() const;
  /// The scene's zenith: --up, else +z, or +y for a glTF scene.
  Triple zenith() const;
  /// The scene's north: --north, else +y, or -z for a glTF scene without --up (east is +x
  /// either way).
  Triple northDirection() const;
  bool usesSun() const
  {
    return !this->sunDirections.empty() || this->sunPath.has_value() || !this->weather.empty();
  }
  /// A scene given without any light: its own emissive surfaces (and the sky) light it.
  bool sceneLightsItself() const
  {
    return !this->usesEmbeddedScene() && !this->usesSun() && this->light.empty() &&
      !this->lightMaterial && !this->pointLight && !this->luminaire;
  }
};

/// Parses argv, fills the defaults that depend on other options and checks the combinations.
/// Throws UsageError.
Options parseCommandLine(int argc, const char* const* argv);

/// Sets the filter's properties from the options, refusing values outside the ranges the
/// filter accepts (it would clamp them silently). Throws UsageError.
void configureFilter(const Options& options, vtkMovingLightRadiosity* filter);

std::string helpText();

} // namespace mlr::cli
