// FrameGraph (core/loops/frame_graph.h): the loop-closure pose graph over submap frames.
// A drifting chain around a square loop is pulled back onto the true frames by one loop
// constraint; a wrong loop constraint among good ones is down-weighted by the kernel; a
// verified loop without a kernel closes a drift of metres;
// a corridor match pulls across the corridor, not along it; capacities refuse and
// count; results are bit-identical across runs; a solve never raises the objective,
// and a rise by rounding at the optimum is no rise; a solve cut short of convergence
// is counted.
#include <cmath>
#include <string>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "loops/frame_graph.h"

using namespace sdpslam;

namespace {

constexpr double kPi = 3.14159265358979323846;

// True frames: 16 submaps 2 m apart around a 8 m × 8 m square (a turn of 90° every 4).
std::vector<Pose2> square_truth() {
  std::vector<Pose2> v;
  Pose2 p;
  for (int k = 0; k < 16; ++k) {
    v.push_back(p);
    const Pose2 step = (k % 4 == 3) ? Pose2{2.0, 0.0, kPi / 2.0} : Pose2{2.0, 0.0, 0.0};
    p = p.compose(step);
  }
  return v;
}

double position_error(const Pose2& a, const Pose2& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

struct Rig {
  alignas(std::max_align_t) unsigned char buffer[1 << 20];
  Arena arena{buffer, sizeof buffer};
  FrameGraph graph;
  std::vector<Pose2> truth = square_truth();
  // Sequential measurements with a heading bias (rad per step): the chain drifts.
  void build_drifting_chain(double bias_rad = 0.02) { build_drifting_chain(graph, bias_rad); }
  void build_drifting_chain(FrameGraph& g, double bias_rad) {
    g.clear();
    Pose2 est = truth[0];
    for (std::size_t k = 0; k < truth.size(); ++k) {
      Pose2 z;
      if (k > 0) {
        z = between(truth[k - 1], truth[k]);
        z.heading_rad += bias_rad;
        est = est.compose(z);
      }
      CHECK_TRUE(g.add_node(k == 0 ? truth[0] : est, z, FrameInfo::from_sigma(0.1, 0.02)));
    }
  }
  // `frames` frames round and round the square, every step turned `bias_rad` too far,
  // and a loop constraint (the truth) one lap back from every `loop_stride`-th frame
  // after the first lap, behind the kernel.
  void build_wound_laps(FrameGraph& g, std::uint32_t frames, double bias_rad, std::uint32_t loop_stride) {
    g.clear();
    const std::uint32_t lap = static_cast<std::uint32_t>(truth.size());
    Pose2 est = truth[0];
    for (std::uint32_t k = 0; k < frames; ++k) {
      Pose2 z;
      if (k > 0U) {
        z = between(truth[(k - 1U) % lap], truth[k % lap]);
        z.heading_rad += bias_rad;
        est = est.compose(z);
      }
      CHECK_TRUE(g.add_node(est, z, FrameInfo::from_sigma(0.05, 0.01)));
    }
    for (std::uint32_t k = lap; k < frames; k += loop_stride) {
      const Pose2 z = between(truth[(k - lap) % lap], truth[k % lap]);
      CHECK_TRUE(g.add_loop(k - lap, k, z, FrameInfo::from_sigma(0.1, 0.02)));
    }
  }
};

}  // namespace

TEST_GROUP(FrameGraph) {
  Rig* rig = nullptr;
  void setup() override {
    rig = new Rig();
    FrameGraphOptions o;
    o.max_nodes = 32U;
    o.max_loops = 8U;
    CHECK_TRUE(rig->graph.init(o, rig->arena));
  }
  void teardown() override { delete rig; }
};

TEST(FrameGraph, a_single_loop_constraint_pulls_a_drifting_square_back_into_shape) {
  rig->build_drifting_chain();
  const std::vector<Pose2>& t = rig->truth;
  const double before = position_error(rig->graph.frame(15), t[15]);
  CHECK_TRUE(before > 1.0);  // the chain alone ends metres off
  // Frame 15 seen from frame 0 (the robot is back near the start): exact, and verified
  // (a constraint metres from the chain enters without a kernel, see below).
  CHECK_TRUE(rig->graph.add_loop(0, 15, between(t[0], t[15]), FrameInfo::from_sigma(0.05, 0.01),
                                 FrameGraph::kNoKernel));
  rig->graph.optimise();
  double worst = 0.0;
  for (std::uint32_t k = 0; k < 16U; ++k) worst = std::fmax(worst, position_error(rig->graph.frame(k), t[k]));
  // The bias is spread over 15 steps: what remains is the bias's curvature, centimetres.
  CHECK_TRUE(worst < 0.25);
  CHECK_TRUE(position_error(rig->graph.frame(15), t[15]) < 0.05);
  CHECK_TRUE(rig->graph.stats().last_chi2_after < rig->graph.stats().last_chi2_before);
  DOUBLES_EQUAL(0.0, position_error(rig->graph.frame(0), t[0]), 0.0);  // the gauge stays
}

TEST(FrameGraph, a_wrong_loop_constraint_among_good_ones_is_down_weighted) {
  rig->build_drifting_chain(0.002);  // drift within the good loops' kernel
  const std::vector<Pose2>& t = rig->truth;
  const FrameInfo info = FrameInfo::from_sigma(0.05, 0.01);
  CHECK_TRUE(rig->graph.add_loop(0, 15, between(t[0], t[15]), info));
  CHECK_TRUE(rig->graph.add_loop(1, 14, between(t[1], t[14]), info));
  CHECK_TRUE(rig->graph.add_loop(0, 14, between(t[0], t[14]), info));
  // A false match 3 m off.
  Pose2 wrong = between(t[4], t[12]);
  wrong.x_m += 3.0;
  CHECK_TRUE(rig->graph.add_loop(4, 12, wrong, info));
  rig->graph.optimise();
  CHECK_TRUE(rig->graph.loop_weight(3) < 0.1);
  CHECK_TRUE(rig->graph.loop_weight(0) > 0.5);
  CHECK_TRUE(position_error(rig->graph.frame(15), t[15]) < 0.3);
}

// A chain that is right, one false loop 5 m off (a corridor's twin): the kernel leaves
// the frames where the chain puts them to within centimetres (Dynamic Covariance
// Scaling: a loop's pull falls off as 1/χ³; a Cauchy kernel's, as 1/χ, moved frame 12
// by 0.4 m here).
TEST(FrameGraph, a_lone_false_loop_far_from_a_good_chain_pulls_almost_nothing) {
  rig->build_drifting_chain(0.0);
  const std::vector<Pose2>& t = rig->truth;
  Pose2 wrong = between(t[4], t[12]);
  wrong.x_m += 5.0;
  CHECK_TRUE(rig->graph.add_loop(4, 12, wrong, FrameInfo::from_sigma(0.1, 0.02)));
  rig->graph.optimise();
  double worst = 0.0;
  for (std::uint32_t k = 0; k < 16U; ++k) worst = std::fmax(worst, position_error(rig->graph.frame(k), t[k]));
  CHECK_TEXT(worst < 0.05, std::to_string(worst).c_str());
  CHECK_TRUE(rig->graph.loop_weight(0) < 0.01);
}

// After a long loop the chain is metres off: with the options' narrow kernel the true
// loop constraint is discounted as an outlier; given a wide kernel of its own it
// closes the loop. Bad kernel scales are refused.
TEST(FrameGraph, a_loop_with_its_own_wide_kernel_closes_a_drift_of_metres) {
  const FrameInfo info = FrameInfo::from_sigma(0.1, 0.02);
  const std::vector<Pose2>& t = rig->truth;
  rig->build_drifting_chain(0.06);
  const double before = position_error(rig->graph.frame(15), t[15]);
  CHECK_TRUE(before > 3.0);
  CHECK_TRUE(rig->graph.add_loop(0, 15, between(t[0], t[15]), info));  // options' scale, 3
  rig->graph.optimise();
  const double narrow = position_error(rig->graph.frame(15), t[15]);
  CHECK_TRUE(rig->graph.loop_weight(0) < 0.1);
  rig->build_drifting_chain(0.06);
  CHECK_TRUE(rig->graph.add_loop(0, 15, between(t[0], t[15]), info, 300.0));
  rig->graph.optimise();
  const double wide = position_error(rig->graph.frame(15), t[15]);
  CHECK_TRUE(rig->graph.loop_weight(0) > 0.5);
  CHECK_TRUE(wide < 0.1);
  CHECK_TRUE(narrow > 5.0 * wide);
  CHECK_FALSE(rig->graph.add_loop(0, 15, Pose2{}, info, -1.0));
  CHECK_FALSE(rig->graph.add_loop(0, 15, Pose2{}, info, std::nan("")));
}

// A verified loop (kNoKernel) enters as plain least squares: full weight however far
// the chain is off, the least-squares limit of an ever wider kernel, and a finite
// objective that decreases. With the robust kernel the same constraint is discounted
// while its residual is large: two loops that both saw a broken chain step (0.45 rad,
// as a turn in a doorway can give) disagree with the chain by metres.
TEST(FrameGraph, a_verified_loop_without_a_kernel_is_plain_least_squares) {
  const FrameInfo info = FrameInfo::from_sigma(0.1, 0.02);
  // A corridor: 16 frames 3 m apart; the chain's step into frame 4 turned 0.45 rad too far.
  std::vector<Pose2> t;
  for (int k = 0; k < 16; ++k) t.push_back(Pose2{3.0 * k, 0.0, 0.0});
  auto solve = [&](double chi) {
    rig->graph.clear();
    Pose2 est = t[0];
    for (std::size_t k = 0; k < t.size(); ++k) {
      Pose2 z;
      if (k > 0) {
        z = between(t[k - 1], t[k]);
        if (k == 4) z.heading_rad += 0.45;
        est = est.compose(z);
      }
      CHECK_TRUE(rig->graph.add_node(k == 0 ? t[0] : est, z, info));
    }
    CHECK_TRUE(position_error(rig->graph.frame(6), t[6]) > 2.0);
    CHECK_TRUE(rig->graph.add_loop(2, 6, between(t[2], t[6]), info, chi));
    CHECK_TRUE(rig->graph.add_loop(3, 7, between(t[3], t[7]), info, chi));
    rig->graph.optimise();
  };
  solve(FrameGraph::kNoKernel);
  DOUBLES_EQUAL(1.0, rig->graph.loop_weight(0), 0.0);
  DOUBLES_EQUAL(1.0, rig->graph.loop_weight(1), 0.0);
  CHECK_TRUE(std::isfinite(rig->graph.stats().last_chi2_before));
  CHECK_TRUE(rig->graph.stats().last_chi2_after < rig->graph.stats().last_chi2_before);
  const Pose2 plain = rig->graph.frame(6);
  CHECK_TRUE(position_error(plain, t[6]) < 0.3);
  solve(1.0e6);
  CHECK_TRUE(position_error(rig->graph.frame(6), plain) < 1e-6);
  // Behind the options' kernel the same two loops, metres from the chain, are taken
  // for outliers: the break stays.
  solve(3.0);
  CHECK_TRUE(rig->graph.loop_weight(0) < 0.1);
  CHECK_TRUE(position_error(rig->graph.frame(6), t[6]) > 1.0);
  CHECK_FALSE(rig->graph.add_loop(0, 15, Pose2{}, info, -FrameGraph::kNoKernel));
}

TEST(FrameGraph, capacities_refuse_and_count_and_bad_indices_are_refused) {
  rig->graph.clear();
  for (std::uint32_t k = 0; k < 32U; ++k) CHECK_TRUE(rig->graph.add_node(Pose2{}, Pose2{}, FrameInfo{}));
  CHECK_FALSE(rig->graph.add_node(Pose2{}, Pose2{}, FrameInfo{}));
  LONGS_EQUAL(1, rig->graph.stats().refused_nodes);
  CHECK_FALSE(rig->graph.add_loop(3, 3, Pose2{}, FrameInfo{}));
  CHECK_FALSE(rig->graph.add_loop(0, 32, Pose2{}, FrameInfo{}));
  for (std::uint32_t k = 0; k < 8U; ++k) CHECK_TRUE(rig->graph.add_loop(0, k + 1U, Pose2{}, FrameInfo{}));
  CHECK_FALSE(rig->graph.add_loop(0, 20, Pose2{}, FrameInfo{}));
  LONGS_EQUAL(3, rig->graph.stats().refused_loops);
  rig->graph.optimise();  // consistent already: nothing moves
  for (std::uint32_t k = 0; k < 32U; ++k) DOUBLES_EQUAL(0.0, rig->graph.frame(k).x_m, 1e-12);
}

TEST(FrameGraph, the_same_graph_gives_bit_identical_frames) {
  const std::vector<Pose2>& t = rig->truth;
  rig->build_drifting_chain();
  rig->graph.add_loop(0, 15, between(t[0], t[15]), FrameInfo::from_sigma(0.05, 0.01));
  rig->graph.optimise();
  std::vector<Pose2> first;
  for (std::uint32_t k = 0; k < 16U; ++k) first.push_back(rig->graph.frame(k));
  rig->build_drifting_chain();
  rig->graph.add_loop(0, 15, between(t[0], t[15]), FrameInfo::from_sigma(0.05, 0.01));
  rig->graph.optimise();
  for (std::uint32_t k = 0; k < 16U; ++k) {
    CHECK_TRUE(first[k].x_m == rig->graph.frame(k).x_m);
    CHECK_TRUE(first[k].y_m == rig->graph.frame(k).y_m);
    CHECK_TRUE(first[k].heading_rad == rig->graph.frame(k).heading_rad);
  }
}

TEST(FrameGraph, invalid_options_and_a_small_arena_are_refused) {
  FrameGraphOptions o;
  o.max_nodes = 1U;
  FrameGraph g;
  CHECK_FALSE(g.init(o, rig->arena));
  LONGS_EQUAL(0, FrameGraph::required_bytes(o));
  alignas(std::max_align_t) unsigned char tiny[256];
  Arena small(tiny, sizeof tiny);
  CHECK_FALSE(g.init(FrameGraphOptions{}, small));
}

// A corridor match fixes the frames across the corridor, not along it
// (FrameInfo::from_directions): its information is rotated into the frame of Z.
TEST(FrameGraph, direction_information_keeps_only_what_the_match_fixes) {
  const double sigma = 0.1, floor = 0.02;
  const FrameInfo iso = FrameInfo::from_sigma(sigma, 0.02);
  // Every direction fixed (M = ½ I): the isotropic constraint, whatever Z's heading.
  const FrameInfo all = FrameInfo::from_directions(sigma, 0.02, 0.5, 0.0, 0.5, floor, 0.7);
  DOUBLES_EQUAL(iso.xx, all.xx, 1e-9 * iso.xx);
  DOUBLES_EQUAL(iso.yy, all.yy, 1e-9 * iso.yy);
  DOUBLES_EQUAL(0.0, all.xy, 1e-9 * iso.xx);
  DOUBLES_EQUAL(iso.theta, all.theta, 0.0);
  // A corridor along 30° in frame i (normals at 120°), Z turned by 50°: in Z's frame the
  // corridor runs along −20°.
  const double deg = kPi / 180.0;
  const double nx = std::cos(120.0 * deg), ny = std::sin(120.0 * deg);
  const FrameInfo c = FrameInfo::from_directions(sigma, 0.02, nx * nx, nx * ny, ny * ny, floor, 50.0 * deg);
  CHECK_TRUE(c.valid());
  auto along = [&](double angle) {  // vᵀ Ω v for the unit vector at `angle`
    const double vx = std::cos(angle), vy = std::sin(angle);
    return c.xx * vx * vx + 2.0 * c.xy * vx * vy + c.yy * vy * vy;
  };
  DOUBLES_EQUAL(floor * iso.xx, along(-20.0 * deg), 1e-9 * iso.xx);
  DOUBLES_EQUAL(iso.xx, along(70.0 * deg), 1e-9 * iso.xx);
  // Nothing is ever more certain than the isotropic constraint.
  const FrameInfo odd = FrameInfo::from_directions(sigma, 0.02, 0.9, 0.3, 0.1, floor, 0.0);
  CHECK_TRUE(odd.xx <= iso.xx * (1.0 + 1e-12) && odd.yy <= iso.yy * (1.0 + 1e-12));
  // Not positive definite, or not finite: refused.
  CHECK_FALSE((FrameInfo{1.0, 1.0, 1.0, 1.0}.valid()));
  CHECK_FALSE((FrameInfo{1.0, 0.0, 1.0, 0.0}.valid()));
  CHECK_FALSE((FrameInfo{std::nan(""), 0.0, 1.0, 1.0}.valid()));
  rig->graph.clear();
  CHECK_TRUE(rig->graph.add_node(Pose2{}, Pose2{}, iso));
  CHECK_TRUE(rig->graph.add_node(Pose2{}, Pose2{}, iso));
  CHECK_FALSE(rig->graph.add_loop(0, 1, Pose2{}, FrameInfo{1.0, 2.0, 1.0, 1.0}));
  CHECK_FALSE(rig->graph.add_node(Pose2{}, Pose2{}, FrameInfo{-1.0, 0.0, 1.0, 1.0}));
}

// A straight corridor of 10 frames 2 m apart, consistent. A loop between its ends that
// slid 1.5 m along the corridor and 0.3 m across it: isotropic, it stretches the chain
// by most of the slide; as a corridor match it moves the end across, hardly along.
TEST(FrameGraph, a_corridor_loop_pulls_across_the_corridor_not_along_it) {
  const double sigma = 0.1;
  const FrameInfo seg = FrameInfo::from_sigma(sigma, 0.02);
  auto solve = [&](const FrameInfo& loop_info) {
    rig->graph.clear();
    for (int k = 0; k < 10; ++k) {
      CHECK_TRUE(rig->graph.add_node(Pose2{2.0 * k, 0.0, 0.0}, k == 0 ? Pose2{} : Pose2{2.0, 0.0, 0.0}, seg));
    }
    CHECK_TRUE(rig->graph.add_loop(0, 9, Pose2{18.0 + 1.5, 0.3, 0.0}, loop_info, 100.0));
    rig->graph.optimise();
    return rig->graph.frame(9);
  };
  const Pose2 iso = solve(FrameInfo::from_sigma(sigma, 0.02));
  // Normals along y: the match fixes y only.
  const Pose2 dir = solve(FrameInfo::from_directions(sigma, 0.02, 0.0, 0.0, 1.0, 0.02, 0.0));
  CHECK_TRUE(iso.x_m - 18.0 > 1.0);        // stretched by most of the slide
  CHECK_TRUE(dir.x_m - 18.0 < 0.3);        // hardly
  CHECK_TRUE(iso.y_m > 0.25 && dir.y_m > 0.25);  // across: pulled either way
}

// Far from the solution the linearised objective is a poor guide, and a full
// Gauss-Newton step can raise the true objective a hundredfold: here a chain of 400
// frames, 25 laps round the square, whose every step turned 0.01 or 0.02 rad too far
// (4 or 8 rad in all), with a loop constraint one lap back from every frame but the
// first lap's, behind the kernel. A solve never ends worse than it started: a step is
// halved until the objective does not rise, or refused.
TEST(FrameGraph, a_solve_never_raises_the_objective_however_far_the_chain_has_wound) {
  FrameGraphOptions o;
  o.max_nodes = 400U;
  o.max_loops = 384U;
  FrameGraph g;
  CHECK_TRUE(g.init(o, rig->arena));
  for (const double bias_rad : {0.01, 0.02}) {
    rig->build_wound_laps(g, o.max_nodes, bias_rad, 1U);
    g.optimise();
    CHECK_TRUE(std::isfinite(g.stats().last_chi2_after));
    CHECK_TRUE(g.stats().last_chi2_after < g.stats().last_chi2_before);  // and it still makes headway
  }
}

// At convergence a step moves the objective by rounding, up as often as down; that is
// no rise: solves that start at the optimum (20 more after each) refuse no step. The
// loops disagree with the chain by a few centimetres, as real matches do, so the
// optimum's objective is not zero and its rounding is not either.
TEST(FrameGraph, a_converged_solve_refuses_no_step_for_rounding) {
  FrameGraphOptions o;
  o.max_nodes = 32U;
  o.max_loops = 8U;
  o.iterations = 50U;
  FrameGraph g;
  CHECK_TRUE(g.init(o, rig->arena));
  const std::vector<Pose2>& t = rig->truth;
  for (const double bias_rad : {0.005, 0.01, 0.02, 0.04}) {
    rig->build_drifting_chain(g, bias_rad);
    for (std::uint32_t q = 0; q < 8U; ++q) {
      const std::uint32_t i = q, j = q + 8U;
      Pose2 z = between(t[i], t[j]);
      z.x_m += 0.03 * static_cast<double>(q % 3U) - 0.03;
      z.y_m += 0.02 * static_cast<double>(q % 2U) - 0.01;
      z.heading_rad += 0.004 * static_cast<double>(q % 4U) - 0.006;
      CHECK_TRUE(g.add_loop(i, j, z, FrameInfo::from_sigma(0.1, 0.02)));
    }
    g.optimise();
    CHECK_TRUE(g.stats().last_chi2_after < g.stats().last_chi2_before);
    CHECK_TRUE(g.stats().last_chi2_after > 1.0);  // the loops disagree: the optimum is not zero
    for (int again = 0; again < 20; ++again) g.optimise();  // each starts at the optimum
  }
  LONGS_EQUAL(0, g.stats().refused_steps);
}

// 25 laps round the square (400 frames) whose every step turned 0.005 rad too far (2 rad
// in all), with a loop constraint one lap back from every 7th frame, behind the kernel.
// Five Gauss-Newton steps leave the objective well above its optimum, and the solve
// says so (capped); fifty reach it and do not; a solve that starts there does not.
TEST(FrameGraph, a_solve_cut_short_of_convergence_is_counted) {
  FrameGraph full;
  FrameGraph cut;
  for (FrameGraph* g : {&full, &cut}) {
    FrameGraphOptions o;
    o.max_nodes = 400U;
    o.max_loops = 64U;
    o.iterations = g == &full ? 50U : 5U;
    CHECK_TRUE(g->init(o, rig->arena));
  }
  rig->build_wound_laps(full, 400U, 0.005, 7U);
  rig->build_wound_laps(cut, 400U, 0.005, 7U);
  full.optimise();
  cut.optimise();
  const double optimum = full.stats().last_chi2_after;
  CHECK_TRUE(cut.stats().last_chi2_after > 5.0 * optimum);
  LONGS_EQUAL(1, cut.stats().capped);
  LONGS_EQUAL(0, full.stats().capped);
  full.optimise();  // from the optimum
  LONGS_EQUAL(0, full.stats().capped);
  DOUBLES_EQUAL(optimum, full.stats().last_chi2_after, FrameGraph::kConverged * optimum);
  LONGS_EQUAL(0, full.stats().refused_steps);
}
