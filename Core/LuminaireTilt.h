// The TILT=INCLUDE factor of every pose: a lamp's output changes with its burning position, so a
// luminaire that the poses tilt emits a factor of its photometered flux.
#pragma once

#include "MovingLight.h"
#include "Photometry.h"
#include "Vec3.h"

#include <string>
#include <vector>

namespace mlr
{

/// The tilt of one posed luminaire as a TILT table indexes it.
struct LuminaireTilt
{
  /// Degrees: for the vertical geometry the angle between the nadir and straight down, in
  /// [0, 180]; for the horizontal ones the signed turn about the photometric horizontal (C0,
  /// x), positive when it swings the nadir towards C90 (+y), in [-180, 180].
  double angle = 0;
  /// Degrees by which the pose leaves the tilts the table describes: for geometry 2 (the lamp
  /// along C0-C180 that only rolls), how far that lamp axis leans out of the horizontal; 0 for
  /// geometries 1 and 3, whose tables describe every burning position of their lamp.
  double untabulated = 0;
};

/**
 * The tilt of a luminaire whose photometric frame is `posed` (world directions) in a scene
 * whose zenith is `up` (any length but 0), for the lamp-to-luminaire geometry `geometry`:
 *  - 1, the lamp along the nadir: the lamp's tilt from vertical is the nadir's from straight
 *    down, whatever the plane it tilts in.
 *  - 3, the lamp along C90-C270 (y): turning about the photometric horizontal by t tilts the
 *    lamp's axis by t out of the horizontal, so the angle is that of y above or below the
 *    horizontal (asin of y . down, with the sign of the turn): exact for any pose, as the
 *    lamp's output follows its own axis alone.
 *  - 2, the lamp along C0-C180 (x): turning about x only rolls the lamp, and the angle is that
 *    roll, the angle from the nadir to straight down about x (atan2(-down . y, down . z));
 *    a pose that leans x out of the horizontal has a lamp tilt the table does not give
 *    (`untabulated`).
 * Throws mlr::Error when `up` is zero or not finite.
 */
LuminaireTilt luminaireTilt(
  TiltTable::Geometry geometry, const PhotometricFrame& posed, const Vec3& up);

/**
 * `poses` with every power factor times its TILT factor: the table's factor at the tilt of
 * the luminaire's photometric frame `own` (before posing) turned by the pose, linear between
 * the tabulated angles and the end factor beyond them. A table of non-negative angles only
 * is taken as symmetric in the sign of a horizontal lamp's turn. Appends to `warnings`, naming
 * `file`, the poses that leave the tabulated range and those geometry 2 cannot describe. The
 * factor enters as the pose's power factor, so that path reuse stays exact (Method.md, 8).
 */
std::vector<LightPose> tiltPoses(const TiltTable& tilt, const PhotometricFrame& own,
  std::vector<LightPose> poses, const Vec3& up, const std::string& file,
  std::vector<std::string>& warnings);

} // namespace mlr
