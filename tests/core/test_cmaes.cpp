#include <gtest/gtest.h>

#include <cmath>

#include <pagmo/algorithms/cmaes.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

double sphere(const Eigen::VectorXd& x) { return x.squaredNorm(); }

double rosenbrock(const Eigen::VectorXd& x) {
  double f = 0.0;
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i)
    f += 100.0 * std::pow(x[i + 1] - x[i] * x[i], 2) + std::pow(1.0 - x[i], 2);
  return f;
}

struct PagmoProblem {
  unsigned dim = 10;
  bool rosen = false;
  pagmo::vector_double fitness(const pagmo::vector_double& v) const {
    const Eigen::Map<const Eigen::VectorXd> x(v.data(), static_cast<Eigen::Index>(v.size()));
    return {rosen ? rosenbrock(x) : sphere(x)};
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    return {pagmo::vector_double(dim, -5.0), pagmo::vector_double(dim, 10.0)};
  }
};

double run_ours(bool rosen, int budget, std::uint64_t seed) {
  CmaesOptions o;
  o.sigma0 = 0.75;  // 5% of the [-5, 10] box, as pagmo's relative sigma0 below
  o.max_evaluations = budget;
  o.seed = seed;
  Cmaes es(Eigen::VectorXd::Constant(10, 3.0), o);
  while (!es.done()) {
    const Eigen::MatrixXd& pop = es.ask();
    std::vector<double> f;
    for (Eigen::Index i = 0; i < pop.rows(); ++i) f.push_back(rosen ? rosenbrock(pop.row(i).transpose()) : sphere(pop.row(i).transpose()));
    es.tell(f);
  }
  return es.best_value();
}

double run_pagmo(bool rosen, int budget, unsigned seed) {
  const unsigned lambda = 4 + static_cast<unsigned>(std::floor(3.0 * std::log(10.0)));
  pagmo::problem prob{PagmoProblem{10, rosen}};
  pagmo::population pop{prob, lambda, seed};
  pagmo::algorithm algo{pagmo::cmaes(static_cast<unsigned>(budget) / lambda, -1, -1, -1, -1, 0.5, 1e-30, 1e-30, false, false, seed)};
  pop = algo.evolve(pop);
  return pop.champion_f()[0];
}

TEST(Cmaes, UsesPycmaDefaults) {
  Cmaes es(Eigen::VectorXd::Zero(150), {});
  EXPECT_EQ(es.population(), 4 + 15);  // 4 + floor(3 ln 150)
  Cmaes small(Eigen::VectorXd::Zero(2), {});
  EXPECT_EQ(small.population(), 6);
}

TEST(Cmaes, SolvesSphereAsWellAsPagmo) {
  const double ours = run_ours(false, 3000, 1), theirs = run_pagmo(false, 3000, 1);
  std::printf("sphere, 3000 evaluations: ours %.3g, pagmo %.3g\n", ours, theirs);
  EXPECT_LT(ours, 1e-10);
  EXPECT_LT(ours, std::max(100.0 * theirs, 1e-14));
}

TEST(Cmaes, SolvesRosenbrockAsWellAsPagmo) {
  const double ours = run_ours(true, 20000, 2), theirs = run_pagmo(true, 20000, 2);
  std::printf("rosenbrock, 20000 evaluations: ours %.3g, pagmo %.3g\n", ours, theirs);
  EXPECT_LT(ours, 1e-6);
  EXPECT_LT(ours, std::max(100.0 * theirs, 1e-6));
}

TEST(Cmaes, SameSeedSameSearchAndBadTellsRejected) {
  EXPECT_EQ(run_ours(true, 2000, 5), run_ours(true, 2000, 5));
  EXPECT_NE(run_ours(true, 2000, 5), run_ours(true, 2000, 6));
  Cmaes es(Eigen::VectorXd::Zero(3), {});
  EXPECT_THROW(es.tell({1.0}), InputError);
  es.ask();
  EXPECT_THROW(es.tell({1.0, 2.0}), InputError);
  std::vector<double> nan(static_cast<std::size_t>(es.population()), 1.0);
  nan[2] = std::nan("");
  EXPECT_THROW(es.tell(nan), InputError);
}

}  // namespace
}  // namespace dicestack
