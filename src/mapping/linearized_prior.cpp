#include "quadric_slam/mapping/linearized_prior.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <stdexcept>

#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

namespace {
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace

int PriorVariable::tangentSize() const {
  return kind == Kind::kPose ? kPoseTangentSize : minimalDimension(quadric_class);
}

int LinearizedPrior::tangentSize() const {
  int size = 0;
  for (const PriorVariable& v : variables)
    size += v.tangentSize();
  return size;
}

int LinearizedPrior::offset(std::size_t i) const {
  int o = 0;
  for (std::size_t j = 0; j < i; ++j)
    o += variables[j].tangentSize();
  return o;
}

int LinearizedPrior::find(PriorVariable::Kind kind, int id) const {
  for (std::size_t i = 0; i < variables.size(); ++i)
    if (variables[i].kind == kind && variables[i].id == id)
      return static_cast<int>(i);
  return -1;
}

LinearizedPrior schurComplementPrior(const std::vector<PriorVariable>& variables,
                                     const std::vector<bool>& eliminate, const Eigen::MatrixXd& H,
                                     const Eigen::VectorXd& g, double relative_threshold) {
  if (variables.size() != eliminate.size())
    throw std::invalid_argument("schurComplementPrior: one eliminate flag per variable");
  if (!(relative_threshold > 0.0))
    throw std::invalid_argument("schurComplementPrior: relative_threshold must be > 0");
  // Tangent indices of the eliminated (m) and kept (r) variables.
  std::vector<int> m_index, r_index;
  LinearizedPrior prior;
  int column = 0;
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const int size = variables[i].tangentSize();
    for (int c = 0; c < size; ++c)
      (eliminate[i] ? m_index : r_index).push_back(column + c);
    if (!eliminate[i])
      prior.variables.push_back(variables[i]);
    column += size;
  }
  if (column != H.rows() || H.rows() != H.cols() || g.size() != H.rows())
    throw std::invalid_argument("schurComplementPrior: H, g and the variables disagree in size");
  if (r_index.empty())
    return {};
  const int nm = static_cast<int>(m_index.size()), nr = static_cast<int>(r_index.size());
  Eigen::MatrixXd Hmm(nm, nm), Hmr(nm, nr), Hrr(nr, nr);
  Eigen::VectorXd gm(nm), gr(nr);
  for (int a = 0; a < nm; ++a) {
    gm[a] = g[m_index[a]];
    for (int b = 0; b < nm; ++b)
      Hmm(a, b) = H(m_index[a], m_index[b]);
    for (int b = 0; b < nr; ++b)
      Hmr(a, b) = H(m_index[a], r_index[b]);
  }
  for (int a = 0; a < nr; ++a) {
    gr[a] = g[r_index[a]];
    for (int b = 0; b < nr; ++b)
      Hrr(a, b) = H(r_index[a], r_index[b]);
  }
  Eigen::MatrixXd H_star = Hrr;
  Eigen::VectorXd g_star = gr;
  if (nm > 0) {
    // H_mm may be singular (a variable seen along a degenerate direction only): its
    // pseudo-inverse eliminates what is observable and leaves the rest without information.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> emm(0.5 * (Hmm + Hmm.transpose()));
    const Eigen::VectorXd s = emm.eigenvalues();
    const double floor = relative_threshold * std::max(s.maxCoeff(), 0.0);
    Eigen::VectorXd s_inverse = Eigen::VectorXd::Zero(nm);
    for (int i = 0; i < nm; ++i)
      if (s[i] > floor && s[i] > 0.0)
        s_inverse[i] = 1.0 / s[i];
    const Eigen::MatrixXd Hmm_pinv =
        emm.eigenvectors() * s_inverse.asDiagonal() * emm.eigenvectors().transpose();
    H_star -= Hmr.transpose() * Hmm_pinv * Hmr;
    g_star -= Hmr.transpose() * Hmm_pinv * gm;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (H_star + H_star.transpose()));
  const Eigen::VectorXd s = es.eigenvalues();
  const double floor = relative_threshold * std::max(s.maxCoeff(), 0.0);
  std::vector<int> kept;
  for (int i = 0; i < nr; ++i)
    if (s[i] > floor && s[i] > 0.0)
      kept.push_back(i);
  if (kept.empty())
    return {};
  const int rows = static_cast<int>(kept.size());
  prior.J.resize(rows, nr);
  prior.r0.resize(rows);
  for (int k = 0; k < rows; ++k) {
    const double sigma = std::sqrt(s[kept[k]]);
    const Eigen::VectorXd v = es.eigenvectors().col(kept[k]);
    prior.J.row(k) = sigma * v.transpose();
    prior.r0[k] = v.dot(g_star) / sigma;
  }
  return prior;
}

LinearizedPrior eliminateVariable(const LinearizedPrior& prior, std::size_t index) {
  std::vector<bool> eliminate(prior.variables.size(), false);
  eliminate.at(index) = true;
  return schurComplementPrior(prior.variables, eliminate, prior.J.transpose() * prior.J,
                              prior.J.transpose() * prior.r0);
}

Eigen::VectorXd priorVariableMinus(const PriorVariable& variable, const double* x) {
  if (variable.kind == PriorVariable::Kind::kPose)
    return minus(poseFromParameters(x), poseFromParameters(variable.x0.data()));  // eq. 14
  Eigen::Matrix<double, 9, 1> general;
  general.head<6>() = minus(poseFromParameters(x), poseFromParameters(variable.x0.data()));
  for (int i = 0; i < 3; ++i)
    general[6 + i] = x[7 + i] - variable.x0[7 + i];
  return basisPseudoInverse(variable.quadric_class) * general;
}

Eigen::MatrixXd priorVariableMinusJacobian(const PriorVariable& variable, const double* x) {
  // x = x exp(d^) moves log(T_x0^-1 T_x) by J_r^-1(e) d, d = MinusJacobian(x) dx.
  const Vector6d e = minus(poseFromParameters(x), poseFromParameters(variable.x0.data()));
  const Matrix6d Jr_inverse = rightJacobianInverseSE3(e);
  if (variable.kind == PriorVariable::Kind::kPose)
    return Jr_inverse * poseMinusJacobian(x);
  Eigen::Matrix<double, 9, 9> general = Eigen::Matrix<double, 9, 9>::Identity();
  general.topLeftCorner<6, 6>() = Jr_inverse;
  return basisPseudoInverse(variable.quadric_class) * general * quadricGeneralMinusJacobian(x);
}

LinearizedPriorCost::LinearizedPriorCost(LinearizedPrior prior) : prior_(std::move(prior)) {
  if (prior_.empty() || prior_.J.cols() != prior_.tangentSize() ||
      prior_.r0.size() != prior_.J.rows())
    throw std::invalid_argument("LinearizedPriorCost: J, r0 and the variables disagree in size");
  set_num_residuals(static_cast<int>(prior_.J.rows()));
  for (const PriorVariable& v : prior_.variables)
    mutable_parameter_block_sizes()->push_back(v.ambientSize());
}

bool LinearizedPriorCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const int rows = num_residuals();
  Eigen::Map<Eigen::VectorXd> e(residuals, rows);
  e = prior_.r0;
  int column = 0;
  for (std::size_t i = 0; i < prior_.variables.size(); ++i) {
    const PriorVariable& v = prior_.variables[i];
    const int size = v.tangentSize();
    const auto Ji = prior_.J.middleCols(column, size);
    e += Ji * priorVariableMinus(v, parameters[i]);
    if (jacobians != nullptr && jacobians[i] != nullptr)
      Eigen::Map<RowMajor>(jacobians[i], rows, v.ambientSize()) =
          Ji * priorVariableMinusJacobian(v, parameters[i]);
    column += size;
  }
  return true;
}

}  // namespace quadric_slam
