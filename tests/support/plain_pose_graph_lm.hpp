#pragma once
// The reference for the pose graph on g2o benchmark graphs: a plain Ceres Levenberg-Marquardt solve with sparse
// Cholesky, written out here with Ceres directly -- stock ceres::EigenQuaternionManifold, Ceres' default solver
// options except the linear solver and the iteration cap, no robust loss -- on the same residual definition
// (backend::RelativePoseFactor with the information io::informationFromG2o gives), from the same start, with the
// first vertex held constant. Used by tests/cli/test_g2o_pose_graph.cpp and bench/bench_pose_graph.cpp.
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <chrono>
#include <map>

#include "backend/pose_factors.hpp"
#include "io/g2o_io.hpp"
#include "io/odometry/g2o_pose_graph.hpp"

namespace drover::test {

struct PlainLmResult {
  bool usable = false;
  double initial_cost = 0, final_cost = 0;  // Ceres cost 0.5 |r|^2
  int iterations = 0;
  double time_ms = 0;
};

inline PlainLmResult plainLevenbergMarquardt(const io::G2oGraph& g2o, int max_iterations) {
  struct Block {
    double p[3], q[4];
  };
  std::map<int, Block> blocks;
  for (const io::G2oVertex& v : g2o.vertices) {
    Block& b = blocks[v.id];
    Eigen::Map<Eigen::Vector3d>{b.p} = v.T_world_vertex.translation();
    Eigen::Map<Eigen::Quaterniond>{b.q} = Eigen::Quaterniond(v.T_world_vertex.linear()).normalized();
  }
  ceres::Problem problem;
  for (const io::G2oEdge& e : g2o.edges) {
    const backend::Matrix6d info = io::informationFromG2o(e.information, e.T_from_to.linear());
    const backend::Matrix6d L = info.llt().matrixU();  // L^T L = info
    Block &a = blocks.at(e.from), &b = blocks.at(e.to);
    problem.AddResidualBlock(new backend::RelativePoseFactor(e.T_from_to, L), nullptr, a.p, a.q, b.p, b.q);
  }
  for (auto& [id, b] : blocks) {
    if (problem.HasParameterBlock(b.q)) problem.SetManifold(b.q, new ceres::EigenQuaternionManifold);
  }
  Block& first = blocks.at(g2o.vertices.front().id);
  if (problem.HasParameterBlock(first.p)) {
    problem.SetParameterBlockConstant(first.p);
    problem.SetParameterBlockConstant(first.q);
  }

  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  const auto start = std::chrono::steady_clock::now();
  ceres::Solve(options, &problem, &summary);
  PlainLmResult r;
  r.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  r.usable = summary.IsSolutionUsable();
  r.initial_cost = summary.initial_cost;
  r.final_cost = summary.final_cost;
  r.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  return r;
}

}  // namespace drover::test
