#include "quadric_slam/mapping/schur_covariance.h"

#include <Eigen/Cholesky>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace quadric_slam {

namespace {

// Inverse of a symmetric positive definite matrix; false when it is not.
bool invertSpd(const Eigen::MatrixXd& m, Eigen::MatrixXd* inverse) {
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (m + m.transpose()));
  if (llt.info() != Eigen::Success)
    return false;
  *inverse = llt.solve(Eigen::MatrixXd::Identity(m.rows(), m.cols()));
  return inverse->allFinite();
}

}  // namespace

bool schurLandmarkCovariances(ceres::Problem* problem,
                              const std::map<int, LandmarkBlock>& landmarks, int max_dense_size,
                              std::map<int, Eigen::MatrixXd>* out) {
  out->clear();
  std::unordered_map<const double*, int> id_of;
  for (const auto& [id, block] : landmarks) {
    if (!problem->HasParameterBlock(block.parameters) ||
        problem->IsParameterBlockConstant(block.parameters) ||
        problem->ParameterBlockTangentSize(block.parameters) != block.minimal_size)
      return false;
    id_of[block.parameters] = id;
  }

  // Landmarks sharing a residual with another landmark (a marginalisation prior) are not
  // block-diagonal in H: they join the dense part.
  std::vector<ceres::ResidualBlockId> residual_blocks;
  problem->GetResidualBlocks(&residual_blocks);
  std::unordered_set<const double*> coupled;
  std::vector<double*> touched;
  for (const ceres::ResidualBlockId residual : residual_blocks) {
    problem->GetParameterBlocksForResidualBlock(residual, &touched);
    int landmarks_touched = 0;
    for (const double* p : touched)
      landmarks_touched += id_of.count(p) > 0 ? 1 : 0;
    if (landmarks_touched >= 2)
      for (const double* p : touched)
        if (id_of.count(p) > 0)
          coupled.insert(p);
  }

  // Columns: the block-diagonal landmarks first, then every other varying block (dense part).
  std::vector<double*> all_blocks;
  problem->GetParameterBlocks(&all_blocks);
  std::vector<double*> order;
  std::vector<int> sparse_ids;      // landmark id of each block-diagonal landmark
  std::vector<int> sparse_offsets;  // its first column
  int columns = 0;
  for (double* p : all_blocks) {
    if (id_of.count(p) == 0 || coupled.count(p) > 0)
      continue;
    order.push_back(p);
    sparse_ids.push_back(id_of.at(p));
    sparse_offsets.push_back(columns);
    columns += problem->ParameterBlockTangentSize(p);
  }
  const int sparse_columns = columns;
  const int num_sparse = static_cast<int>(sparse_ids.size());
  std::map<int, int> dense_offset_of;  // id -> first dense column, for the coupled landmarks
  for (double* p : all_blocks) {
    if ((id_of.count(p) > 0 && coupled.count(p) == 0) || problem->IsParameterBlockConstant(p))
      continue;
    if (id_of.count(p) > 0)
      dense_offset_of[id_of.at(p)] = columns - sparse_columns;
    order.push_back(p);
    columns += problem->ParameterBlockTangentSize(p);
  }
  const int dense_size = columns - sparse_columns;
  if (dense_size > max_dense_size)
    return false;

  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = order;
  options.apply_loss_function = true;  // as ceres::Covariance
  ceres::CRSMatrix J;
  double cost = 0;
  if (!problem->Evaluate(options, &cost, nullptr, nullptr, &J) || J.num_cols != columns)
    return false;

  // Owner of each column: a block-diagonal landmark's index, or -1 (dense part).
  std::vector<int> owner(columns, -1), local(columns);
  for (int s = 0; s < num_sparse; ++s) {
    const int end = s + 1 < num_sparse ? sparse_offsets[s + 1] : sparse_columns;
    for (int c = sparse_offsets[s]; c < end; ++c) {
      owner[c] = s;
      local[c] = c - sparse_offsets[s];
    }
  }
  for (int c = sparse_columns; c < columns; ++c)
    local[c] = c - sparse_columns;

  // H = J^T J by blocks: Hll (per landmark), Hld (landmark x dense), Hdd.
  std::vector<Eigen::MatrixXd> Hll(num_sparse), Hld(num_sparse);
  for (int s = 0; s < num_sparse; ++s) {
    const int k = landmarks.at(sparse_ids[s]).minimal_size;
    Hll[s] = Eigen::MatrixXd::Zero(k, k);
    Hld[s] = Eigen::MatrixXd::Zero(k, dense_size);
  }
  Eigen::MatrixXd Hdd = Eigen::MatrixXd::Zero(dense_size, dense_size);
  for (int r = 0; r < J.num_rows; ++r) {
    const int begin = J.rows[r], end = J.rows[r + 1];
    for (int a = begin; a < end; ++a) {
      const int ca = J.cols[a];
      const double va = J.values[a];
      for (int b = begin; b < end; ++b) {
        const int cb = J.cols[b];
        const double product = va * J.values[b];
        if (owner[ca] >= 0) {
          if (owner[cb] == owner[ca])
            Hll[owner[ca]](local[ca], local[cb]) += product;
          else if (owner[cb] < 0)
            Hld[owner[ca]](local[ca], local[cb]) += product;
          else
            return false;  // two block-diagonal landmarks in one row: not the assumed structure
        } else if (owner[cb] < 0) {
          Hdd(local[ca], local[cb]) += product;
        }
      }
    }
  }

  // S = Hdd - sum Hld^T Hll^-1 Hld; the landmark's terms A = Hll^-1, B = A Hld kept.
  std::vector<Eigen::MatrixXd> A(num_sparse), B(num_sparse);
  Eigen::MatrixXd S = Hdd;
  for (int s = 0; s < num_sparse; ++s) {
    if (!invertSpd(Hll[s], &A[s]))
      return false;
    B[s] = A[s] * Hld[s];
    S.noalias() -= Hld[s].transpose() * B[s];
  }
  Eigen::MatrixXd S_inverse;
  if (dense_size > 0 && !invertSpd(S, &S_inverse))
    return false;

  for (int s = 0; s < num_sparse; ++s) {
    Eigen::MatrixXd covariance = A[s];
    if (dense_size > 0)
      covariance.noalias() += B[s] * S_inverse * B[s].transpose();
    const Eigen::MatrixXd checked = acceptedCovariance(covariance);
    if (checked.size() > 0)
      (*out)[sparse_ids[s]] = checked;
  }
  for (const auto& [id, offset] : dense_offset_of) {
    const int k = landmarks.at(id).minimal_size;
    const Eigen::MatrixXd checked = acceptedCovariance(S_inverse.block(offset, offset, k, k));
    if (checked.size() > 0)
      (*out)[id] = checked;
  }
  return true;
}

}  // namespace quadric_slam
