#include "quadric_slam/io/pipeline_params.h"

namespace quadric_slam {

void readNormalEstimationParams(const ParamReader& reader, BackProjectionParams& back_projection,
                                NormalEstimator::Params& normals, ParamLog& log) {
  readParam(reader, "decimation", back_projection.decimation, log);
  readParam(reader, "min_range", back_projection.min_range, log);
  readParam(reader, "max_range", back_projection.max_range, log);
  readParam(reader, "normal_method", normals.method, log);
  readParam(reader, "max_depth_change_factor", normals.max_depth_change_factor, log);
  readParam(reader, "normal_smoothing_size", normals.normal_smoothing_size, log);
  readParam(reader, "depth_dependent_smoothing", normals.depth_dependent_smoothing, log);
  readParam(reader, "threads", normals.threads, log);
  back_projection.validate();
  normals.validate();
}

}  // namespace quadric_slam
