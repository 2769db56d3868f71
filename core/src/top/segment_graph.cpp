// Probabilistic Graph of Segments; see segment_graph.h for the contract.
#include "top/segment_graph.h"

#include <limits>

namespace sdpslam {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

bool finite_positive(double v) { return v > 0.0 && v < kInfinity; }
bool unit_interval(double u) { return u >= 0.0 && u < 1.0; }

// Inverse-CDF pick over weights[0..n): the first i whose cumulative weight exceeds
// u·total. Falls back to the last index (u·total can round up to total).
template <typename WeightAt>
std::uint32_t pick(std::uint32_t n, double u, WeightAt weight_at) {
  double total = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) total += weight_at(i);
  const double target = u * total;
  double cumulative = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    cumulative += weight_at(i);
    if (target < cumulative) return i;
  }
  return n - 1U;
}

}  // namespace

bool SegmentGraphOptions::valid() const {
  return max_levels >= 2U && max_levels <= capacity::kMaxPgsLevels && nodes_per_level >= 1U &&
         nodes_per_level <= capacity::kMaxPgsNodesPerLevel && finite_positive(prior_error_m) &&
         finite_positive(error_floor_m) &&
         (accumulation == PgsAccumulation::kSum || accumulation == PgsAccumulation::kMean);
}

const char* to_string(PgsStatus status) {
  switch (status) {
    case PgsStatus::kOk: return "ok";
    case PgsStatus::kNotInitialised: return "not initialised";
    case PgsStatus::kFull: return "graph full";
    case PgsStatus::kNoLevel: return "level not live";
    case PgsStatus::kBadNode: return "node index out of range";
    case PgsStatus::kBadArgument: return "bad argument";
  }
  return "unknown";
}

std::size_t SegmentGraph::required_bytes(const SegmentGraphOptions& options) {
  if (!options.valid()) return 0U;
  const std::uint64_t l = options.max_levels;
  const std::uint64_t n = options.nodes_per_level;
  const std::uint64_t bytes = l * n * sizeof(PgsNode) + l * n * n * sizeof(Edge) + l * sizeof(std::uint32_t) +
                              n * sizeof(Edge) + 4U * 16U;
  if (bytes > static_cast<std::uint64_t>(std::numeric_limits<std::size_t>::max())) return 0U;
  return static_cast<std::size_t>(bytes);
}

bool SegmentGraph::init(const SegmentGraphOptions& options, Arena& arena) {
  const std::size_t need = required_bytes(options);
  if (initialised() || need == 0U || arena.available_bytes() < need) return false;
  const std::size_t l = options.max_levels;
  const std::size_t n = options.nodes_per_level;
  PgsNode* nodes = arena.allocate_array<PgsNode>(l * n);
  Edge* edges = arena.allocate_array<Edge>(l * n * n);
  auto* level_nodes = arena.allocate_array<std::uint32_t>(l);
  Edge* anchor_edges = arena.allocate_array<Edge>(n);
  if (nodes == nullptr || edges == nullptr || level_nodes == nullptr || anchor_edges == nullptr) return false;
  options_ = options;
  edges_ = edges;
  level_nodes_ = level_nodes;
  anchor_edges_ = anchor_edges;
  nodes_ = nodes;  // last: initialised() keys on it
  return true;
}

std::uint32_t SegmentGraph::node_count(std::uint32_t level) const {
  if (!initialised() || !is_live(level)) return 0U;
  return level_nodes_[slot_of(level)];
}

const PgsNode* SegmentGraph::node(std::uint32_t level, std::uint32_t index) const {
  if (index >= node_count(level)) return nullptr;
  return &nodes_[static_cast<std::size_t>(slot_of(level)) * options_.nodes_per_level + index];
}

PgsLevelResult SegmentGraph::add_level(const PgsNodeInput* nodes, std::uint32_t count) {
  PgsLevelResult r;
  if (!initialised()) {
    r.status = refuse(PgsStatus::kNotInitialised);
    return r;
  }
  if (nodes == nullptr || count == 0U || count > options_.nodes_per_level) {
    r.status = refuse(PgsStatus::kBadArgument);
    return r;
  }
  if (live_count_ == options_.max_levels) {
    ++full_count_;
    r.status = PgsStatus::kFull;
    return r;
  }
  const std::uint32_t level = level_end();
  const std::uint32_t n = options_.nodes_per_level;
  ++live_count_;
  if (live_count_ > peak_live_) peak_live_ = live_count_;
  const std::uint32_t slot = slot_of(level);
  level_nodes_[slot] = count;
  for (std::uint32_t i = 0; i < count; ++i) {
    PgsNode& dst = nodes_[static_cast<std::size_t>(slot) * n + i];
    dst.particle_id = nodes[i].particle_id;
    dst.level = level;
    dst.index = i;
    dst.initial_pose = nodes[i].initial_pose;
    dst.final_pose = nodes[i].final_pose;
  }
  // The new level's own outgoing edges start clean for when the next level arrives.
  Edge* own = &edges_[static_cast<std::size_t>(slot) * n * n];
  for (std::size_t e = 0; e < static_cast<std::size_t>(n) * n; ++e) own[e] = Edge{};
  if (live_count_ == 1U) {
    for (std::uint32_t i = 0; i < n; ++i) anchor_edges_[i] = Edge{};
  }
  r.status = PgsStatus::kOk;
  r.level = level;
  return r;
}

const SegmentGraph::Edge* SegmentGraph::edge_ptr(std::uint32_t level, std::uint32_t a, std::uint32_t b) const {
  if (!initialised() || !is_live(level) || !is_live(level + 1U)) return nullptr;
  if (a >= node_count(level) || b >= node_count(level + 1U)) return nullptr;
  const std::size_t n = options_.nodes_per_level;
  return &edges_[static_cast<std::size_t>(slot_of(level)) * n * n + a * n + b];
}

double SegmentGraph::effective_error(const Edge& e) const {
  double err = options_.prior_error_m;
  if (e.samples > 0U) {
    err = options_.accumulation == PgsAccumulation::kSum ? e.error_sum_m
                                                         : e.error_sum_m / static_cast<double>(e.samples);
  }
  return err < options_.error_floor_m ? options_.error_floor_m : err;
}

PgsStatus SegmentGraph::record_error(std::uint32_t level, std::uint32_t a, std::uint32_t b, double error_m) {
  if (!initialised()) return refuse(PgsStatus::kNotInitialised);
  if (!(error_m >= 0.0 && error_m < kInfinity)) return refuse(PgsStatus::kBadArgument);
  if (!is_live(level) || !is_live(level + 1U)) return refuse(PgsStatus::kNoLevel);
  Edge* e = edge_ptr(level, a, b);
  if (e == nullptr) return refuse(PgsStatus::kBadNode);
  e->error_sum_m += error_m;
  ++e->samples;
  return PgsStatus::kOk;
}

PgsStatus SegmentGraph::record_chain_error(std::uint32_t first_level, const std::uint32_t* choices,
                                           std::uint32_t count, double error_m) {
  if (!initialised()) return refuse(PgsStatus::kNotInitialised);
  if (choices == nullptr || count < 2U || !(error_m >= 0.0 && error_m < kInfinity)) {
    return refuse(PgsStatus::kBadArgument);
  }
  if (!is_live(first_level) || count > level_end() - first_level) return refuse(PgsStatus::kNoLevel);
  for (std::uint32_t i = 0; i < count; ++i) {
    if (choices[i] >= node_count(first_level + i)) return refuse(PgsStatus::kBadNode);
  }
  for (std::uint32_t i = 0; i + 1U < count; ++i) {
    Edge* e = edge_ptr(first_level + i, choices[i], choices[i + 1U]);
    e->error_sum_m += error_m;
    ++e->samples;
  }
  return PgsStatus::kOk;
}

double SegmentGraph::edge_error(std::uint32_t level, std::uint32_t a, std::uint32_t b) const {
  const Edge* e = edge_ptr(level, a, b);
  return e != nullptr ? effective_error(*e) : -1.0;
}

std::uint32_t SegmentGraph::edge_sample_count(std::uint32_t level, std::uint32_t a, std::uint32_t b) const {
  const Edge* e = edge_ptr(level, a, b);
  return e != nullptr ? e->samples : 0U;
}

double SegmentGraph::pair_probability(std::uint32_t level, std::uint32_t a, std::uint32_t b) const {
  const Edge* target = edge_ptr(level, a, b);
  if (target == nullptr) return -1.0;
  const std::uint32_t na = node_count(level);
  const std::uint32_t nb = node_count(level + 1U);
  double total = 0.0;
  for (std::uint32_t i = 0; i < na; ++i) {
    for (std::uint32_t j = 0; j < nb; ++j) total += weight(*edge_ptr(level, i, j));
  }
  return weight(*target) / total;
}

template <class LevelsLive>
PgsStatus SegmentGraph::check_sampling(double u, LevelsLive&& levels_live) const {
  if (!initialised()) return refuse(PgsStatus::kNotInitialised);
  if (!unit_interval(u)) return refuse(PgsStatus::kBadArgument);
  if (!levels_live()) return refuse(PgsStatus::kNoLevel);
  return PgsStatus::kOk;
}

PgsPairPick SegmentGraph::sample_pair(std::uint32_t level, double u) const {
  PgsPairPick r;
  r.status = check_sampling(u, [&] { return is_live(level) && is_live(level + 1U); });
  if (r.status != PgsStatus::kOk) return r;
  const std::uint32_t nb = node_count(level + 1U);
  const std::uint32_t flat = pick(node_count(level) * nb, u, [&](std::uint32_t k) {
    return weight(*edge_ptr(level, k / nb, k % nb));
  });
  r.status = PgsStatus::kOk;
  r.node_a = flat / nb;
  r.node_b = flat % nb;
  return r;
}

PgsPick SegmentGraph::sample_next(std::uint32_t level, std::uint32_t a, double u) const {
  PgsPick r;
  r.status = check_sampling(u, [&] { return is_live(level) && is_live(level + 1U); });
  if (r.status != PgsStatus::kOk) return r;
  if (a >= node_count(level)) {
    r.status = refuse(PgsStatus::kBadNode);
    return r;
  }
  r.node = pick(node_count(level + 1U), u, [&](std::uint32_t b) { return weight(*edge_ptr(level, a, b)); });
  r.status = PgsStatus::kOk;
  return r;
}

PgsPick SegmentGraph::sample_previous(std::uint32_t level, std::uint32_t b, double u) const {
  PgsPick r;
  r.status = check_sampling(u, [&] { return level != 0U && is_live(level) && is_live(level - 1U); });
  if (r.status != PgsStatus::kOk) return r;
  if (b >= node_count(level)) {
    r.status = refuse(PgsStatus::kBadNode);
    return r;
  }
  const std::uint32_t prev = level - 1U;
  r.node = pick(node_count(prev), u, [&](std::uint32_t a) { return weight(*edge_ptr(prev, a, b)); });
  r.status = PgsStatus::kOk;
  return r;
}

PgsPick SegmentGraph::sample_first(double u) const {
  PgsPick r;
  r.status = check_sampling(u, [&] { return live_count_ != 0U; });
  if (r.status != PgsStatus::kOk) return r;
  const std::uint32_t level = first_live_;
  const std::uint32_t n = node_count(level);
  if (has_anchor()) {
    r.node = pick(n, u, [&](std::uint32_t b) { return weight(anchor_edges_[b]); });
  } else if (live_count_ >= 2U) {
    const std::uint32_t nb = node_count(level + 1U);
    r.node = pick(n, u, [&](std::uint32_t a) {
      double row = 0.0;
      for (std::uint32_t b = 0; b < nb; ++b) row += weight(*edge_ptr(level, a, b));
      return row;
    });
  } else {
    r.node = pick(n, u, [](std::uint32_t) { return 1.0; });
  }
  r.status = PgsStatus::kOk;
  return r;
}

Pose2 SegmentGraph::transform_between(const PgsNode& a, const PgsNode& b) {
  return a.final_pose.compose(b.initial_pose.inverse());
}

PgsStatus SegmentGraph::transform_between(std::uint32_t level, std::uint32_t a, std::uint32_t b, Pose2& out) const {
  if (!initialised()) return refuse(PgsStatus::kNotInitialised);
  if (!is_live(level) || !is_live(level + 1U)) return refuse(PgsStatus::kNoLevel);
  const PgsNode* na = node(level, a);
  const PgsNode* nb = node(level + 1U, b);
  if (na == nullptr || nb == nullptr) return refuse(PgsStatus::kBadNode);
  out = transform_between(*na, *nb);
  return PgsStatus::kOk;
}

PgsStatus SegmentGraph::compose_chain(const std::uint32_t* choices, std::uint32_t count, Pose2* out_poses) const {
  if (!initialised()) return refuse(PgsStatus::kNotInitialised);
  if (choices == nullptr || out_poses == nullptr || count == 0U) return refuse(PgsStatus::kBadArgument);
  if (count > live_count_) return refuse(PgsStatus::kNoLevel);
  for (std::uint32_t i = 0; i < count; ++i) {
    if (choices[i] >= node_count(first_live_ + i)) return refuse(PgsStatus::kBadNode);
  }
  const PgsNode* prev = node(first_live_, choices[0]);
  out_poses[0] = has_anchor() ? anchor_frame_.compose(transform_between(anchor_, *prev)) : Pose2{};
  for (std::uint32_t i = 1; i < count; ++i) {
    const PgsNode* cur = node(first_live_ + i, choices[i]);
    out_poses[i] = out_poses[i - 1U].compose(transform_between(*prev, *cur));
    prev = cur;
  }
  return PgsStatus::kOk;
}

PgsPermanentResult SegmentGraph::make_oldest_permanent(std::uint32_t chosen) {
  PgsPermanentResult r;
  if (!initialised()) {
    r.status = refuse(PgsStatus::kNotInitialised);
    return r;
  }
  if (live_count_ == 0U) {
    r.status = refuse(PgsStatus::kNoLevel);
    return r;
  }
  const std::uint32_t level = first_live_;
  const std::uint32_t n_level = node_count(level);
  if (chosen >= n_level) {
    r.status = refuse(PgsStatus::kBadNode);
    return r;
  }
  const PgsNode& node_ref = *node(level, chosen);
  const Pose2 frame = has_anchor() ? anchor_frame_.compose(transform_between(anchor_, node_ref)) : Pose2{};
  const std::uint32_t n_next = live_count_ >= 2U ? node_count(level + 1U) : 0U;
  for (std::uint32_t b = 0; b < options_.nodes_per_level; ++b) {
    anchor_edges_[b] = b < n_next ? *edge_ptr(level, chosen, b) : Edge{};
  }
  anchor_ = node_ref;
  anchor_frame_ = frame;
  r.node = anchor_;
  r.frame_in_global = frame;
  r.released_nodes = n_level - 1U;
  r.released_edges = n_level * n_next;
  // Release the slot.
  const std::uint32_t slot = head_;
  level_nodes_[slot] = 0U;
  head_ = (head_ + 1U) % options_.max_levels;
  ++first_live_;
  --live_count_;
  ++permanent_count_;
  r.status = PgsStatus::kOk;
  return r;
}

std::uint32_t SegmentGraph::live_node_count() const {
  std::uint32_t total = 0U;
  for (std::uint32_t k = first_live_; k < level_end(); ++k) total += node_count(k);
  return total;
}

std::uint32_t SegmentGraph::live_edge_count() const {
  std::uint32_t total = 0U;
  for (std::uint32_t k = first_live_; k + 1U < level_end(); ++k) total += node_count(k) * node_count(k + 1U);
  return total;
}

bool SegmentGraph::invariants_hold() const {
  if (!initialised()) return edges_ == nullptr && level_nodes_ == nullptr && live_count_ == 0U;
  if (edges_ == nullptr || level_nodes_ == nullptr || anchor_edges_ == nullptr) return false;
  const std::uint32_t l = options_.max_levels;
  const std::uint32_t n = options_.nodes_per_level;
  if (live_count_ > l || peak_live_ < live_count_ || peak_live_ > l || head_ >= l) return false;
  // Levels only leave the graph by becoming permanent.
  if (permanent_count_ != first_live_) return false;
  if (has_anchor() && anchor_.level + 1U != first_live_) return false;
  // Live slots hold 1..n nodes labelled with their level and index; free slots hold none.
  for (std::uint32_t s = 0; s < l; ++s) {
    const std::uint32_t offset = (s + l - head_) % l;
    const bool live = offset < live_count_;
    const std::uint32_t count = level_nodes_[s];
    if (!live) {
      if (count != 0U) return false;
      continue;
    }
    if (count == 0U || count > n) return false;
    const std::uint32_t level = first_live_ + offset;
    for (std::uint32_t i = 0; i < count; ++i) {
      const PgsNode& nd = nodes_[static_cast<std::size_t>(s) * n + i];
      if (nd.level != level || nd.index != i) return false;
    }
  }
  // Every live edge is sane: errors finite and non-negative, zero when never sampled.
  const auto sane = [](const Edge& e) {
    if (!(e.error_sum_m >= 0.0 && e.error_sum_m < kInfinity)) return false;
    return e.samples > 0U || e.error_sum_m == 0.0;
  };
  for (std::uint32_t k = first_live_; k + 1U < level_end(); ++k) {
    for (std::uint32_t a = 0; a < node_count(k); ++a) {
      for (std::uint32_t b = 0; b < node_count(k + 1U); ++b) {
        if (!sane(*edge_ptr(k, a, b))) return false;
      }
    }
  }
  for (std::uint32_t b = 0; b < n; ++b) {
    if (!sane(anchor_edges_[b])) return false;
  }
  return true;
}

void SegmentGraph::transfer_state(StateIo& io) {
  io.section("segment_graph");
  io.value(anchor_);
  io.value(anchor_frame_);
  io.value(head_);
  io.value(first_live_);
  io.value(live_count_);
  io.value(peak_live_);
  io.value(permanent_count_);
  io.value(full_count_);
  io.value(misuse_count_);
}

}  // namespace sdpslam
