// The moving light: diffuse emitting polygons translated to one position per frame.
#pragma once

#include "Rgb.h"
#include "Vec3.h"

#include <cstddef>
#include <vector>

namespace mlr
{

/// One triangle of the light, in the light's own frame (before translation).
struct LightTriangle
{
  Vec3 a, b, c;
  Vec3 normal; ///< unit, right-hand rule: the emitting side
  double area = 0;
};

/**
 * A planar polygonal light (one or more simple polygons, convex or concave) with total power
 * Phi (RGB, W), emitting diffusely from the front side of each polygon, and the translation
 * t_k that places it in frame k. Power is spread uniformly over the area (exitance Phi/A_L).
 * The light does not occlude. The constructor throws mlr::Error naming what is wrong.
 */
class MovingLight
{
public:
  MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
    const std::vector<Vec3>& translations);

  const Rgb& power() const { return this->Power; }
  double area() const { return this->Area; }
  /// Area centroid of the light as given (frame-independent reference point).
  const Vec3& centroid() const { return this->Centroid; }
  const std::vector<LightTriangle>& triangles() const { return this->Triangles; }

  std::size_t frameCount() const { return this->Translations.size(); }
  const Vec3& translation(std::size_t frame) const { return this->Translations[frame]; }
  const std::vector<Vec3>& translations() const { return this->Translations; }

  /// A uniformly distributed point on the light (own frame) and the normal there.
  void samplePoint(double u0, double u1, double u2, Vec3& point, Vec3& normal) const;

private:
  Rgb Power;
  double Area = 0;
  Vec3 Centroid;
  std::vector<LightTriangle> Triangles;
  std::vector<double> CumulativeArea;
  std::vector<Vec3> Translations;
};

} // namespace mlr
