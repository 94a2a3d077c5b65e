// Choosing the best impostor plane (steed-ibr-impostors-lecture, part 2, "Choosing the best impostor plane": errors
// are proportional to the distance from the projection plane, and the best orientation depends on the samples).
#pragma once

#include <span>

#include "farfield/core/math.h"
#include "farfield/impostor/validity_metrics.h"

namespace farfield::impostor {

struct BestPlane {
  ImpostorPlane plane;   // through the samples' centroid, normal towards the capture eye
  double rms_distance = 0.0;  // root mean square distance of the samples from the plane, metres
  double max_distance = 0.0;  // largest distance, metres
};

// The plane that minimises the mean squared distance of `points` among the planes whose normal lies within
// `max_tilt` radians (0..pi/2) of the direction from the centroid to `capture_eye` (a plane seen too obliquely
// gives the image no texels). For any normal the best such plane goes through the centroid; the normal is the
// covariance's smallest eigenvector when it lies in that cone, else the best normal on the cone's rim. Throws
// farfield::Error for no points, a non-finite point, max_tilt out of range, or a capture eye at the centroid.
BestPlane bestPlane(std::span<const DVec3> points, const DVec3& capture_eye, double max_tilt = degToRad(60.0));

// Mean squared distance of the points from the plane through their centroid with unit normal n (the objective).
double meanSquaredDistance(std::span<const DVec3> points, const DVec3& n);

}  // namespace farfield::impostor
