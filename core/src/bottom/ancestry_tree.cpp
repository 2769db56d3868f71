// Ancestry tree: prune/merge of paper §II-A, DFS interval labels, path commitment.
#include "sdpslam/core/bottom/ancestry_tree.h"

namespace sdpslam {

namespace {

// Worst-case arena bytes of an ArenaPool<T>: slots, two u32 bookkeeping arrays and the
// padding each of the three allocations may need.
template <typename T>
std::size_t pool_bytes(std::uint32_t capacity) {
  return PoolOf<T>::kSlotSize * capacity + 2U * sizeof(std::uint32_t) * capacity + alignof(T) +
         2U * alignof(std::uint32_t);
}

}  // namespace

std::size_t AncestryTree::required_arena_bytes(std::uint32_t node_capacity, std::uint32_t path_entry_capacity) {
  return pool_bytes<Node>(node_capacity) + pool_bytes<PathEntry>(path_entry_capacity) +
         sizeof(Label) * node_capacity + alignof(Label) + sizeof(NodeId) * node_capacity + alignof(NodeId);
}

bool AncestryTree::init(Arena& arena, std::uint32_t node_capacity, std::uint32_t path_entry_capacity) {
  capacity_ = 0U;
  if (node_capacity == 0U || path_entry_capacity == 0U || node_capacity >= 0x7FFFFFFFU) return false;
  if (!nodes_.init(arena, node_capacity) || !paths_.init(arena, path_entry_capacity)) return false;
  labels_ = arena.allocate_array<Label>(node_capacity);
  scratch_ = arena.allocate_array<NodeId>(node_capacity);
  if (labels_ == nullptr || scratch_ == nullptr) return false;
  capacity_ = node_capacity;
  first_root_ = kNoNode;
  last_root_ = kNoNode;
  active_count_ = 0U;
  label_counter_ = 0U;
  tree_counter_ = 0U;
  pruned_ = false;
  return true;
}

NodeId AncestryTree::allocate_node(NodeId parent) {
  if (capacity_ == 0U) {
    ++node_oom_count_;
    return kNoNode;
  }
  Node* n = nodes_.create();
  if (n == nullptr) {
    ++node_oom_count_;
    return kNoNode;
  }
  const NodeId id = nodes_.index_of(n);
  n->parent = parent;
  if (parent == kNoNode) {
    n->prev_sibling = last_root_;
    if (last_root_ != kNoNode) {
      node(last_root_).next_sibling = id;
    } else {
      first_root_ = id;
    }
    last_root_ = id;
  } else {
    Node& p = node(parent);
    n->next_sibling = p.first_child;
    if (p.first_child != kNoNode) node(p.first_child).prev_sibling = id;
    p.first_child = id;
    ++p.child_count;
  }
  ++active_count_;
  pruned_ = false;
  return id;
}

NodeId AncestryTree::create_root() {
  const NodeId id = allocate_node(kNoNode);
  if (id == kNoNode) return kNoNode;
  // A new root gets a fresh interval disjoint from every existing one, so it is
  // labelled at once and its provisional descendants can anchor on it.
  Label& l = labels_[id];
  l.pre = ++label_counter_;
  l.post = l.pre;
  l.depth = 0U;
  l.anchor = id;
  l.tree = ++tree_counter_;
  return id;
}

NodeId AncestryTree::add_child(NodeId parent) {
  if (!contains(parent)) {
    ++misuse_count_;
    return kNoNode;
  }
  const NodeId id = allocate_node(parent);
  if (id == kNoNode) return kNoNode;
  Label& l = labels_[id];
  l.pre = 0U;
  l.post = 0U;
  l.depth = labels_[parent].depth + 1U;
  l.anchor = labels_[parent].anchor;
  l.tree = labels_[parent].tree;
  return id;
}

bool AncestryTree::set_active(NodeId id, bool active) {
  if (!contains(id)) {
    ++misuse_count_;
    return false;
  }
  Node& n = node(id);
  if (n.active != active) {
    n.active = active;
    if (active) {
      ++active_count_;
    } else {
      --active_count_;
    }
    pruned_ = false;
  }
  return true;
}

bool AncestryTree::is_active(NodeId id) const { return contains(id) && node(id).active; }
NodeId AncestryTree::parent(NodeId id) const { return contains(id) ? node(id).parent : kNoNode; }
NodeId AncestryTree::first_child(NodeId id) const { return contains(id) ? node(id).first_child : kNoNode; }
NodeId AncestryTree::next_sibling(NodeId id) const { return contains(id) ? node(id).next_sibling : kNoNode; }
std::uint32_t AncestryTree::child_count(NodeId id) const { return contains(id) ? node(id).child_count : 0U; }

bool AncestryTree::provisional_is_ancestor(NodeId ancestor, NodeId descendant) const {
  // `ancestor` was added since the last relabel, so only nodes added after it (all
  // unlabelled) can descend from it: climb the unlabelled part of `descendant`'s path.
  const std::uint32_t target_depth = labels_[ancestor].depth;
  for (NodeId x = descendant; x != kNoNode && labels_[x].anchor != x; x = node(x).parent) {
    if (x == ancestor) return true;
    if (labels_[x].depth <= target_depth) return false;
  }
  return false;
}

void AncestryTree::unlink(NodeId id) {
  Node& n = node(id);
  if (n.prev_sibling != kNoNode) {
    node(n.prev_sibling).next_sibling = n.next_sibling;
  } else if (n.parent != kNoNode) {
    node(n.parent).first_child = n.next_sibling;
  } else {
    first_root_ = n.next_sibling;
  }
  if (n.next_sibling != kNoNode) {
    node(n.next_sibling).prev_sibling = n.prev_sibling;
  } else if (n.parent == kNoNode) {
    last_root_ = n.prev_sibling;
  }
  if (n.parent != kNoNode) --node(n.parent).child_count;
  n.prev_sibling = kNoNode;
  n.next_sibling = kNoNode;
  n.parent = kNoNode;
}

void AncestryTree::replace_in_parent(NodeId old_id, NodeId new_id) {
  Node& o = node(old_id);
  Node& n = node(new_id);
  n.parent = o.parent;
  n.prev_sibling = o.prev_sibling;
  n.next_sibling = o.next_sibling;
  if (o.prev_sibling != kNoNode) {
    node(o.prev_sibling).next_sibling = new_id;
  } else if (o.parent != kNoNode) {
    node(o.parent).first_child = new_id;
  } else {
    first_root_ = new_id;
  }
  if (o.next_sibling != kNoNode) {
    node(o.next_sibling).prev_sibling = new_id;
  } else if (o.parent == kNoNode) {
    last_root_ = new_id;
  }
  o.parent = kNoNode;
  o.prev_sibling = kNoNode;
  o.next_sibling = kNoNode;
}

void AncestryTree::free_path(NodeId id) {
  Node& n = node(id);
  std::uint32_t e = n.path_head;
  while (e != kNoNode) {
    PathEntry* pe = paths_.at_index(e);
    e = pe->next;
    paths_.destroy(pe);
  }
  n.path_head = kNoNode;
  n.path_tail = kNoNode;
  n.path_count = 0U;
}

std::uint32_t AncestryTree::prune(TreeListener* listener) {
  std::uint32_t released = 0U;
  if (capacity_ == 0U || first_root_ == kNoNode) {
    pruned_ = true;
    return 0U;
  }
  // Post-order walk over the links (no recursion, no stack): children are settled
  // before their parent, so a removal that empties a parent and a merge that leaves a
  // grandparent with one child are both seen when the walk reaches that node.
  auto leftmost_leaf = [this](NodeId x) {
    while (node(x).first_child != kNoNode) x = node(x).first_child;
    return x;
  };
  NodeId x = leftmost_leaf(first_root_);
  while (x != kNoNode) {
    const Node& nx = node(x);
    const NodeId next = nx.next_sibling != kNoNode ? leftmost_leaf(nx.next_sibling) : nx.parent;
    if (!nx.active && nx.child_count == 0U) {
      if (listener != nullptr) listener->on_node_removed(x);
      free_path(x);
      unlink(x);
      nodes_.destroy(&node(x));
      ++released;
    } else if (!nx.active && nx.child_count == 1U) {
      const NodeId c = nx.first_child;
      if (listener != nullptr) listener->on_node_merged(x, c);
      Node& p = node(x);
      Node& ch = node(c);
      if (p.path_count > 0U) {  // the parent's poses are older: prepend them, O(1)
        paths_.at_index(p.path_tail)->next = ch.path_head;
        if (ch.path_head == kNoNode) ch.path_tail = p.path_tail;
        ch.path_head = p.path_head;
        ch.path_count += p.path_count;
        p.path_head = kNoNode;
        p.path_tail = kNoNode;
        p.path_count = 0U;
      }
      unlink(c);
      replace_in_parent(x, c);
      nodes_.destroy(&node(x));
      ++released;
    }
    x = next;
  }
  relabel();
  pruned_ = true;
  return released;
}

void AncestryTree::relabel() {
  // Euler-tour numbering: pre on entry, post on exit, one counter, so a node's interval
  // [pre, post] contains exactly its descendants' intervals (O(1) ancestor test).
  std::uint32_t counter = 0U;
  NodeId x = first_root_;
  while (x != kNoNode) {
    const Node& n = node(x);
    Label& l = labels_[x];
    l.pre = counter++;
    l.depth = n.parent == kNoNode ? 0U : labels_[n.parent].depth + 1U;
    l.anchor = x;
    if (n.first_child != kNoNode) {
      x = n.first_child;
      continue;
    }
    // Leaf: close it and every ancestor whose last child this was.
    for (;;) {
      labels_[x].post = counter++;
      const Node& m = node(x);
      if (m.next_sibling != kNoNode) {
        x = m.next_sibling;
        break;
      }
      x = m.parent;
      if (x == kNoNode) break;
    }
  }
  label_counter_ = counter;
}

bool AncestryTree::append_pose(NodeId id, std::int64_t stamp_us, const Pose2& pose) {
  if (!contains(id)) {
    ++misuse_count_;
    return false;
  }
  PathEntry* e = paths_.create();
  if (e == nullptr) {
    ++path_oom_count_;
    return false;
  }
  e->stamp_us = stamp_us;
  e->pose = pose;
  e->next = kNoNode;
  const std::uint32_t idx = paths_.index_of(e);
  Node& n = node(id);
  if (n.path_tail != kNoNode) {
    paths_.at_index(n.path_tail)->next = idx;
  } else {
    n.path_head = idx;
  }
  n.path_tail = idx;
  ++n.path_count;
  return true;
}

std::uint32_t AncestryTree::pose_count(NodeId id) const { return contains(id) ? node(id).path_count : 0U; }

bool AncestryTree::last_pose(NodeId id, std::int64_t* stamp_us, Pose2* pose) const {
  if (!contains(id)) return false;
  for (NodeId x = id; x != kNoNode; x = node(x).parent) {
    const Node& n = node(x);
    if (n.path_tail != kNoNode) {
      const PathEntry& e = path_entry(n.path_tail);
      if (stamp_us != nullptr) *stamp_us = e.stamp_us;
      if (pose != nullptr) *pose = e.pose;
      return true;
    }
  }
  return false;
}

std::uint32_t AncestryTree::drain_committed(PoseSink& sink) {
  std::uint32_t emitted = 0U;
  for (NodeId r = first_root_; r != kNoNode; r = node(r).next_sibling) {
    Node& n = node(r);
    const bool sole_leaf = n.child_count == 0U && n.active && r == first_root_ && n.next_sibling == kNoNode;
    if (n.child_count < 2U && !sole_leaf) continue;
    while (n.path_count > 1U) {  // keep the newest so that last_pose() always answers
      PathEntry* e = paths_.at_index(n.path_head);
      sink.on_committed(e->stamp_us, e->pose);
      n.path_head = e->next;
      --n.path_count;
      paths_.destroy(e);
      ++emitted;
    }
  }
  committed_count_ += emitted;
  return emitted;
}

std::size_t AncestryTree::footprint_bytes() const {
  return nodes_.footprint_bytes() + paths_.footprint_bytes() +
         static_cast<std::size_t>(capacity_) * (sizeof(Label) + sizeof(NodeId));
}

bool AncestryTree::invariants_hold() const {
  if (capacity_ == 0U) return nodes_.size() == 0U && first_root_ == kNoNode;
  if (!nodes_.invariants_hold() || !paths_.invariants_hold()) return false;
  if (nodes_.capacity() != capacity_) return false;
  std::uint32_t reachable = 0U;
  std::uint32_t active = 0U;
  std::uint64_t path_total = 0U;
  // Pre-order walk over the links; `reachable` bounds it so a cycle cannot hang it.
  NodeId prev_root = kNoNode;
  for (NodeId r = first_root_; r != kNoNode; r = node(r).next_sibling) {
    if (!contains(r) || node(r).parent != kNoNode || node(r).prev_sibling != prev_root) return false;
    prev_root = r;
    NodeId x = r;
    for (;;) {
      if (++reachable > nodes_.size()) return false;
      const Node& n = node(x);
      const Label& l = labels_[x];
      if (n.active) ++active;
      // children: back links, count, label nesting and sibling disjointness
      std::uint32_t kids = 0U;
      NodeId prev = kNoNode;
      for (NodeId c = n.first_child; c != kNoNode; c = node(c).next_sibling) {
        if (!contains(c) || node(c).parent != x || node(c).prev_sibling != prev) return false;
        if (++kids > capacity_) return false;
        const Label& lc = labels_[c];
        if (lc.depth != l.depth + 1U || lc.tree != l.tree) return false;
        if (lc.anchor == c) {
          if (l.anchor != x || !(l.pre < lc.pre && lc.post < l.post)) return false;
          if (prev != kNoNode && labels_[prev].anchor == prev && !(labels_[prev].post < lc.pre)) return false;
        } else if (lc.anchor != l.anchor) {
          return false;
        }
        prev = c;
      }
      if (kids != n.child_count) return false;
      if (l.anchor == x && l.pre > l.post) return false;
      if (pruned_ && (l.anchor != x || (!n.active && n.child_count < 2U))) return false;
      // own path list
      std::uint32_t count = 0U;
      std::uint32_t last = kNoNode;
      for (std::uint32_t e = n.path_head; e != kNoNode; e = path_entry(e).next) {
        if (!paths_.slot_in_use(e) || ++count > paths_.size()) return false;
        last = e;
      }
      if (count != n.path_count || last != n.path_tail) return false;
      path_total += count;
      // advance in pre-order within this root's tree
      if (n.first_child != kNoNode) {
        x = n.first_child;
        continue;
      }
      while (x != r && node(x).next_sibling == kNoNode) x = node(x).parent;
      if (x == r) break;
      x = node(x).next_sibling;
    }
  }
  if (prev_root != last_root_) return false;
  if (reachable != nodes_.size()) return false;  // no orphan, no leak
  if (active != active_count_) return false;
  if (path_total != paths_.size()) return false;
  if (pruned_ && (active == 0U ? nodes_.size() != 0U : nodes_.size() > 2U * active - 1U)) return false;
  // Root intervals are disjoint (roots are siblings too).
  for (NodeId r = first_root_; r != kNoNode; r = node(r).next_sibling) {
    const NodeId s = node(r).next_sibling;
    if (s != kNoNode && labels_[r].anchor == r && labels_[s].anchor == s && labels_[r].post >= labels_[s].pre) {
      return false;
    }
  }
  return true;
}


void AncestryTree::transfer_state(StateIo& io) {
  io.section("ancestry_tree");
  nodes_.transfer_state(io);
  paths_.transfer_state(io);
  io.value(first_root_);
  io.value(last_root_);
  io.value(active_count_);
  io.value(label_counter_);
  io.value(tree_counter_);
  io.value(node_oom_count_);
  io.value(path_oom_count_);
  io.value(misuse_count_);
  io.value(committed_count_);
  io.value(pruned_);
}

}  // namespace sdpslam
