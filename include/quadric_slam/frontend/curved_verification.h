// Step 3 of the segmenter: each curved candidate of step 2 (curved_candidates.h), biggest first, is
// refined on its free points, re-assigned to the largest connected set of free pixels that fit it,
// put through model selection (a simpler class that fits almost as well wins), and kept only when
// it is no plane in disguise, its residuals are noise rather than shape, on its support and on the
// unsegmented surface it continues into without a depth jump (else an ellipsoid is sought there,
// class general), and its RMS is within the sensor's noise; and the checks it uses.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "quadric_slam/frontend/curved_candidates.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/segmentation_frame.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace quadric_slam {

// Whether a shape is finite and its size within the Params' plausible range for its class (sphere
// and cylinder radii, cone half angle; planes and general quadrics always).
bool plausibleShape(const PrimitiveShape& s, const QuadricSegmenter::Params& p);

// Pixels of the frame's free points inside roi that lie within the distance threshold of shape
// and whose normal agrees; the largest 4-connected component of them, with the large components on
// the surface's other face. When eligible is given, every pixel that passed that test (in any
// component) is appended to it: the result depends on the frame's used flags through those pixels
// only, so it stays the same while none of them is taken.
std::vector<int> assignLargestComponent(const SegmentationFrame& frame, const PrimitiveShape& shape,
                                        const ImageRoi& roi, const QuadricSegmenter::Params& p,
                                        std::vector<int>* eligible = nullptr);

// Moves a curved shape's origin to the foot of the supporting points' centroid on its axis (the
// cylinder's point is free along the axis) so that extents are centred. A general quadric is put
// in its canonical axis order (central_quadric.h) instead: the refinement may have swapped the
// lengths of two axes.
void centreOnSupport(PrimitiveShape& s, const std::vector<Eigen::Vector3d>& points);

// Called for each detection kept: its supporting pixels and its fit. It must mark the pixels used
// in the frame (later candidates only take free pixels).
using AcceptDetection =
    std::function<void(const std::vector<int>& indices, const ShapeRefiner::Result& fit)>;

// Verifies the candidates in order (biggest first), calling accept for each one kept. With
// p.threads > 1 the verdicts are first reached in parallel against the free pixels before this
// stage; one that an earlier kept candidate could have changed (it took one of the candidate's
// samples, or a pixel that fitted the candidate's shape in one of its assignments) is verified
// again in order, so the result is the sequential one. Returns how many were verified again.
int verifyCurvedCandidates(const SegmentationFrame& frame, const CurvedCandidates& candidates,
                           const QuadricSegmenter::Params& p, const ShapeRefiner& refiner,
                           const AcceptDetection& accept);

}  // namespace quadric_slam
