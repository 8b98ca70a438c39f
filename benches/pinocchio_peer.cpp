// The Pinocchio side of benches/compare_pinocchio.py: Pinocchio's C++ algorithms one call at a
// time over the samples the script wrote, timed in this process. Built by the script against
// the headers and libraries of the `pin` wheel (and Eigen); not part of the library.
//
//   pinocchio_peer MODEL.bin DIR K REPEATS
//   pinocchio_peer MODEL.bin DIR K serve
//
// MODEL.bin: the model saved by pinocchio.Model.saveToBinary. DIR holds q.bin, qd.bin, qdd.bin
// and tau.bin (K x nv float64, row-major). Each pass computes every sample with one call and
// stores its results in a row-major K-sample output (both timed: what a batch costs); prints
// one JSON line per kernel: {"kernel", "ns_per_call" (median over REPEATS passes)}. PEER_KERNELS (a list of names) limits the kernels.
//
// With `serve` in place of REPEATS the process stays, so that the script can take Pinocchio's
// passes and its own in close turns: each line "KERNEL SAMPLES MIN_MS [fresh]" on standard input
// runs one untimed pass over the first SAMPLES samples (as the script's own untimed call), then
// timed passes until MIN_MS milliseconds (at most 60,000) have gone, and prints {"kernel",
// "ns_per_call" (the timed passes' mean)}; an unknown kernel or a bad line (NaN, a number out
// of range, a word for a number or for `fresh`) prints {"error"}. With `fresh`, the pass first
// moves its memory: the samples, Data and the kernel's output are allocated anew (the old
// freed after), as the script does for its own side each round, so that each round draws the
// memory's placement anew (which decides 10-20 % of a kernel's time on a virtual machine, now
// and then far more, and held for a whole run when the memory stayed put). End of input ends
// the process.
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/regressor.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/serialization.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using Clock = std::chrono::steady_clock;

static std::vector<double> read_all(const std::string& path, size_t count) {
  std::vector<double> v(count);
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f || std::fread(v.data(), sizeof(double), count, f) != count) {
    std::fprintf(stderr, "cannot read %zu values from %s\n", count, path.c_str());
    std::exit(2);
  }
  std::fclose(f);
  return v;
}

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: pinocchio_peer MODEL.bin DIR K REPEATS\n");
    return 2;
  }
  pinocchio::Model model;
  model.loadFromBinary(argv[1]);
  // Pinocchio's work buffers, made anew by `fresh` (through the pointer: Data's assignment
  // copies into the buffers it has, so it cannot move them)
  auto held = std::make_unique<pinocchio::Data>(model);
  pinocchio::Data* dp = held.get();
  const std::string dir = argv[2];
  const long k = std::atol(argv[3]);
  const bool serve = std::string(argv[4]) == "serve";
  const int repeats = serve ? 1 : std::atoi(argv[4]);
  const long n = model.nv;
  if (model.nq != model.nv || k <= 0 || repeats <= 0) {
    std::fprintf(stderr, "needs nq == nv, K > 0, REPEATS > 0 or serve\n");
    return 2;
  }
  auto q = read_all(dir + "/q.bin", k * n), qd = read_all(dir + "/qd.bin", k * n),
       qdd = read_all(dir + "/qdd.bin", k * n), tau = read_all(dir + "/tau.bin", k * n);
  using Map = Eigen::Map<const Eigen::VectorXd>;
  auto at = [&](const std::vector<double>& x, long s) { return Map(x.data() + s * n, n); };
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);

  // each kernel: compute sample s (timed), then store sample s's results (untimed pass)
  struct Kernel {
    std::string name;
    long per_sample;
    std::function<void(long)> compute;
    std::function<void(long, double*)> store;
  };
  auto copy = [](const Eigen::MatrixXd& m, double* out) {  // row-major
    for (long r = 0; r < m.rows(); ++r)
      for (long c = 0; c < m.cols(); ++c) out[r * m.cols() + c] = m(r, c);
  };
  Eigen::MatrixXd gs(n, n);
  std::vector<Kernel> kernels = {
      {"rnea", n, [&](long s) { pinocchio::rnea(model, *dp, at(q, s), at(qd, s), at(qdd, s)); },
       [&](long, double* o) { Eigen::Map<Eigen::VectorXd>(o, n) = dp->tau; }},
      {"mass_matrix", n * n,
       [&](long s) { pinocchio::crba(model, *dp, at(q, s), pinocchio::Convention::WORLD); },
       [&](long, double* o) {
         Eigen::MatrixXd m = dp->M;
         m.triangularView<Eigen::StrictlyLower>() = m.transpose().triangularView<Eigen::StrictlyLower>();
         copy(m, o);
       }},
      {"regressor", n * 10 * (model.njoints - 1),
       [&](long s) {
         pinocchio::computeJointTorqueRegressor(model, *dp, at(q, s), at(qd, s), at(qdd, s));
       },
       [&](long, double* o) { copy(dp->jointTorqueRegressor, o); }},
      {"forward_dynamics", n,
       [&](long s) { pinocchio::aba(model, *dp, at(q, s), at(qd, s), at(tau, s), pinocchio::Convention::WORLD); },
       [&](long, double* o) { Eigen::Map<Eigen::VectorXd>(o, n) = dp->ddq; }},
      {"rnea_derivatives", n + 3 * n * n,
       [&](long s) { pinocchio::computeRNEADerivatives(model, *dp, at(q, s), at(qd, s), at(qdd, s)); },
       [&](long, double* o) {
         Eigen::Map<Eigen::VectorXd>(o, n) = dp->tau;
         copy(dp->dtau_dq, o + n);
         copy(dp->dtau_dv, o + n + n * n);
         Eigen::MatrixXd m = dp->M;
         m.triangularView<Eigen::StrictlyLower>() = m.transpose().triangularView<Eigen::StrictlyLower>();
         copy(m, o + n + 2 * n * n);
       }},
      // the local model: the derivatives at the point and the gravity derivative at rest
      {"linearize", n + 4 * n * n,
       [&](long s) {
         pinocchio::computeRNEADerivatives(model, *dp, at(q, s), at(qd, s), at(qdd, s));
         pinocchio::computeGeneralizedGravityDerivatives(model, *dp, at(q, s), gs);
       },
       [&](long, double* o) {
         Eigen::Map<Eigen::VectorXd>(o, n) = dp->tau;
         Eigen::MatrixXd m = dp->M;
         m.triangularView<Eigen::StrictlyLower>() = m.transpose().triangularView<Eigen::StrictlyLower>();
         copy(m, o + n);
         copy(dp->dtau_dv, o + n + n * n);
         copy(dp->dtau_dq, o + n + 2 * n * n);
         copy(gs, o + n + 3 * n * n);
       }},
  };
  // one pass: every sample of the first `count` computed and its results stored in the
  // batch's output, as a user of a batch gets them (and as perturbid_rs's batched kernels
  // deliver them); ns per sample
  auto pass = [&](Kernel& kern, long count, std::vector<double>& out) {
    auto t0 = Clock::now();
    for (long s = 0; s < count; ++s) {
      kern.compute(s);
      kern.store(s, out.data() + s * kern.per_sample);
    }
    return std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / count;
  };
  if (serve) {
    std::map<std::string, std::vector<double>> outs;  // kept from one request to the next
    std::string line;
    while (std::getline(std::cin, line)) {
      std::istringstream words(line);
      std::string name;
      long count = 0;
      double min_ms = 0;
      std::string fresh, rest;
      words >> name >> count >> min_ms;
      const bool read = static_cast<bool>(words);
      words >> fresh >> rest;  // optional; nothing may follow it
      auto kern = std::find_if(kernels.begin(), kernels.end(),
                               [&](const Kernel& x) { return x.name == name; });
      if (!read || kern == kernels.end() || count <= 0 || count > k || !(min_ms >= 0) ||
          min_ms > 60000 || !(fresh.empty() || fresh == "fresh") || !rest.empty()) {
        std::printf(
            "{\"error\": \"expected KERNEL SAMPLES MIN_MS [fresh], SAMPLES <= %ld, MIN_MS <= "
            "60000\"}\n",
            k);
        std::fflush(stdout);
        continue;
      }
      auto& out = outs[name];
      if (!fresh.empty()) {
        // new blocks made while the old are held, so that they cannot be the same
        std::vector<double> q2(q), qd2(qd), qdd2(qdd), tau2(tau), out2(count * kern->per_sample);
        auto data2 = std::make_unique<pinocchio::Data>(model);
        q.swap(q2), qd.swap(qd2), qdd.swap(qdd2), tau.swap(tau2), out.swap(out2);
        held.swap(data2), dp = held.get();
      }
      out.resize(count * kern->per_sample);
      pass(*kern, count, out);  // untimed
      double total = 0;
      long passes = 0;
      auto t0 = Clock::now();
      do {
        total += pass(*kern, count, out);
        ++passes;
      } while (std::chrono::duration<double, std::milli>(Clock::now() - t0).count() < min_ms);
      std::printf("{\"kernel\": \"%s\", \"ns_per_call\": %.3f}\n", name.c_str(),
                  total / passes);
      std::fflush(stdout);
    }
    return 0;
  }
  const char* only = std::getenv("PEER_KERNELS");
  for (auto& kern : kernels) {
    if (only && std::string(only).find(kern.name) == std::string::npos) continue;
    std::vector<double> passes, out(k * kern.per_sample);
    for (int r = 0; r < repeats; ++r) passes.push_back(pass(kern, k, out));
    std::sort(passes.begin(), passes.end());
    std::printf("{\"kernel\": \"%s\", \"ns_per_call\": %.3f}\n", kern.name.c_str(),
                passes[passes.size() / 2]);
    std::fflush(stdout);
  }
  return 0;
}
