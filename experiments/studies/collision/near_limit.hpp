#pragma once
// Near-limit reference loops of the collision benchmark (issue 31 item 4):
// the least code that does the same work as collision::collide (full
// traversal, fast path, FIFO, no filter, no cap) and collision::update_spheres,
// on the same data, so that the library's overhead over the work itself can
// be measured. Nothing here is used by the library; the CTest
// CollisionStudies.NearLimit* checks that these loops and the library give
// identical pairs, test counts and spheres.
#include <cmath>
#include <cstdint>
#include <vector>

#include <icd/collision/sphere_tree.hpp>
#include <icd/collision/traversal.hpp>

namespace icd::collision::experiments {

/// A tree as packed arrays: spheres (x, y, z, r) and, per node, its first
/// child and child count side by side.
struct PackedTree {
  struct Node {
    int32_t first;
    int32_t count;
  };
  std::vector<Node> nodes;
  explicit PackedTree(const SphereTree& t) : nodes(t.spheres.size()) {
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i] = {t.first_child[i], t.child_count[i]};
  }
};

/// Full breadth-first traversal, children tested when their pair is
/// generated (the order of collide()'s fast path: FIFO, the split node
/// alternating per Fig. 7, a leaf's partner split instead). Storage is kept
/// between calls.
class NearLimitTraversal {
 public:
  std::vector<NodePair> colliding;
  int64_t tests = 0;

  void run(const Sphere* sa, const PackedTree& ta, const Sphere* sb, const PackedTree& tb) {
    const PackedTree::Node* na = ta.nodes.data();
    const PackedTree::Node* nb = tb.nodes.data();
    colliding.clear();
    tests = 1;
    std::size_t size = 0;
    if (!overlap(sa[0], sb[0])) return;
    if (na[0].count == 0 && nb[0].count == 0) {
      colliding.push_back({0, 0});
      return;
    }
    reserve(1);
    m_q[size++] = {0, 0, 1};
    for (std::size_t head = 0; head < size; ++head) {
      const Item p = m_q[head];
      const bool eb = nb[p.b].count > 0;
      const bool split_b = p.split_b ? eb : na[p.a].count == 0 && eb;
      if (split_b) {
        const Sphere o = sa[p.a];
        const bool oe = na[p.a].count > 0;
        const int32_t first = nb[p.b].first, end = first + nb[p.b].count;
        tests += end - first;
        if (m_q.size() < size + (end - first)) reserve(size + (end - first));
        Item* q = m_q.data();
        for (int32_t c = first; c < end; ++c) {
          const Sphere& k = sb[c];
          const double dx = o.x - k.x, dy = o.y - k.y, dz = o.z - k.z, rr = o.r + k.r;
          const bool ov = dx * dx + dy * dy + dz * dz <= rr * rr;
          if (oe || nb[c].count > 0) {
            q[size] = {p.a, c, 0};
            size += ov;
          } else if (ov) {
            colliding.push_back({p.a, c});
          }
        }
      } else {
        const Sphere o = sb[p.b];
        const bool oe = eb;
        const int32_t first = na[p.a].first, end = first + na[p.a].count;
        tests += end - first;
        if (m_q.size() < size + (end - first)) reserve(size + (end - first));
        Item* q = m_q.data();
        for (int32_t c = first; c < end; ++c) {
          const Sphere& k = sa[c];
          const double dx = o.x - k.x, dy = o.y - k.y, dz = o.z - k.z, rr = o.r + k.r;
          const bool ov = dx * dx + dy * dy + dz * dz <= rr * rr;
          if (oe || na[c].count > 0) {
            q[size] = {c, p.b, 1};
            size += ov;
          } else if (ov) {
            colliding.push_back({c, p.b});
          }
        }
      }
    }
  }

 private:
  struct Item {
    int32_t a, b, split_b;
  };
  void reserve(std::size_t n) {
    if (m_q.size() < n) m_q.resize(std::max<std::size_t>(2 * n, 1024));
  }
  std::vector<Item> m_q;
};

/// The paper update (ratio) or the displacement bound of update_spheres(),
/// same arithmetic in the same order, into `out` (one sphere per node): the
/// coarse displacements u_j = x_j - X_j are formed once per node first.
/// `X`, `x`: coarse rest / current positions, #Vc x 3 row-major (MatX3d),
/// `nc` rows.
class NearLimitUpdate {
 public:
  void run(const SphereTree& t, const double* X, const double* x, int64_t nc, bool ratio,
           Sphere* out) {
    m_u.resize(static_cast<std::size_t>(3 * nc));
    double* u = m_u.data();
    for (int64_t j = 0; j < 3 * nc; ++j) u[j] = x[j] - X[j];
    const int32_t* off = t.assoc_offset.data();
    const int32_t* nodes = t.assoc_nodes.data();
    const double* d0s = t.assoc_rest_dist.data();
    const Sphere* rest = t.rest_spheres.data();
    const int n = t.num_nodes();
    for (int i = 0; i < n; ++i) {
      const int32_t b = off[i], e = off[i + 1];
      const Sphere rs = rest[i];
      double ux = 0, uy = 0, uz = 0;
      for (int32_t k = b; k < e; ++k) {
        const int32_t j = nodes[k];
        ux += u[3 * j];
        uy += u[3 * j + 1];
        uz += u[3 * j + 2];
      }
      const double inv = 1.0 / (e - b);
      ux *= inv;
      uy *= inv;
      uz *= inv;
      Sphere s;
      s.x = rs.x + ux;
      s.y = rs.y + uy;
      s.z = rs.z + uz;
      if (ratio) {
        double lambda2 = 0.0;
        bool any = false;
        for (int32_t k = b; k < e; ++k) {
          const int32_t j = nodes[k];
          const double d0 = d0s[k];
          if (d0 <= 1e-12 * (rs.r + 1e-300)) continue;
          const double dx = x[3 * j] - s.x, dy = x[3 * j + 1] - s.y, dz = x[3 * j + 2] - s.z;
          lambda2 = std::max(lambda2, (dx * dx + dy * dy + dz * dz) / (d0 * d0));
          any = true;
        }
        s.r = (any ? std::sqrt(lambda2) : 1.0) * rs.r + 0.0;
      } else {
        double dev2 = 0.0;
        for (int32_t k = b; k < e; ++k) {
          const int32_t j = nodes[k];
          const double dx = u[3 * j] - ux, dy = u[3 * j + 1] - uy, dz = u[3 * j + 2] - uz;
          dev2 = std::max(dev2, dx * dx + dy * dy + dz * dz);
        }
        s.r = rs.r + std::sqrt(dev2) + 0.0;
      }
      out[i] = s;
    }
  }

 private:
  std::vector<double> m_u;
};

}  // namespace icd::collision::experiments
