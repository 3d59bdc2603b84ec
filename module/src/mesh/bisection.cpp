#include <meccano/mesh/bisection.hpp>

#include <meccano/error.hpp>

#include <algorithm>
#include <string>

namespace meccano {
namespace {

// Shape regularity bounds every dihedral angle of a bisection mesh of the Kuhn cube below by 45
// degrees, so at most 8 tets share an edge; the margin covers meshes built some other way.
constexpr int max_patch_size = 64;
// Recursion depth grows with the level difference between neighbours, a few dozen at most on a
// compatible mesh; a deeper chain means refinement edges that never match (an incompatible macro mesh).
constexpr int max_recursion_depth = 512;

struct PatchTet {
  TetId slot;    // parent index, then child 0
  TetId child1;  // appended index
  std::array<VertexId, 4> v;
  std::array<TetId, 4> n;
  std::array<FaceTag, 4> tags;
  TetKind kind;
};

class Bisector {
 public:
  Bisector(TetMesh& mesh, const ChildCallback& on_child, std::vector<std::uint8_t>* pending)
      : mesh_(mesh), on_child_(on_child), pending_(pending) {}

  // Bisects `t` once, after recursively bisecting every tet of its refinement patch that does not
  // share its refinement edge. Returns as soon as `t` has been bisected, here or deeper down.
  void bisect(TetId t, int depth = 0) {
    if (depth > max_recursion_depth)
      throw MeshingError("Kossaczky recursion does not terminate: the refinement edges of neighbouring tets "
                         "do not match (the macro mesh violates the matching condition)");
    const auto before = mesh_.tets[t];
    std::array<TetId, max_patch_size> patch{};
    for (;;) {
      const VertexId a = mesh_.tets[t][0];
      const VertexId b = mesh_.tets[t][1];
      const int size = collect_patch(t, a, b, patch);
      for (int i = 0; i < size; ++i)
        if (!mesh_.bisectable(patch[i]))
          throw MeshingError("tet " + std::to_string(patch[i]) +
                             " was made by a topological operation and is not part of the bisection hierarchy");
      const auto incompatible = std::find_if(patch.begin(), patch.begin() + size, [&](TetId p) {
        const auto& v = mesh_.tets[p];
        return !((v[0] == a && v[1] == b) || (v[0] == b && v[1] == a));
      });
      if (incompatible == patch.begin() + size) {
        bisect_patch({patch.data(), static_cast<std::size_t>(size)}, a, b);
        return;
      }
      bisect(*incompatible, depth + 1);
      if (mesh_.tets[t] != before) return;  // bisected inside the recursion
    }
  }

  std::int64_t bisections() const { return bisections_; }
  void record_children_in(std::vector<TetId>* created) { created_ = created; }

 private:
  // The tets around edge (a, b), starting from t (see tets_around_edge; this version avoids allocation).
  int collect_patch(TetId t, VertexId a, VertexId b, std::array<TetId, max_patch_size>& patch) const {
    int size = 0;
    patch[size++] = t;
    auto walk = [&](int first_exit) -> bool {
      TetId previous = t;
      TetId current = mesh_.neighbours[t][first_exit];
      while (current != no_tet && current != t) {
        if (size == max_patch_size) throw MeshingError("an edge is shared by more than 64 tets");
        patch[size++] = current;
        const auto& v = mesh_.tets[current];
        const auto& n = mesh_.neighbours[current];
        TetId next = no_tet;
        for (int i = 0; i < 4; ++i)
          if (v[i] != a && v[i] != b && n[i] != previous) next = n[i];
        previous = current;
        current = next;
      }
      return current == t;
    };
    // Faces 2 and 3 of t contain its refinement edge (a, b).
    if (!walk(2)) walk(3);
    return size;
  }

  static TetId child_containing(const PatchTet& p, VertexId vertex) { return p.v[0] == vertex ? p.slot : p.child1; }

  void bisect_patch(std::span<const TetId> patch, VertexId a, VertexId b) {
    const VertexId m = add_midpoint(a, b);
    std::array<PatchTet, max_patch_size> record{};
    const int size = static_cast<int>(patch.size());
    for (int i = 0; i < size; ++i) {
      const TetId p = patch[i];
      record[i] = {p, mesh_.num_tets() + i, mesh_.tets[p], mesh_.neighbours[p], mesh_.face_tags[p], mesh_.kinds[p]};
    }
    auto find = [&](TetId tet) -> const PatchTet* {
      for (int i = 0; i < size; ++i)
        if (record[i].slot == tet) return &record[i];
      return nullptr;  // outside the patch: not across faces 2 or 3
    };
    // Sub-face of parent face f (2 or 3) on the side of `vertex`: a child of the patch neighbour.
    auto across = [&](const PatchTet& p, int f, VertexId vertex) -> TetId {
      const PatchTet* q = find(p.n[f]);
      return q ? child_containing(*q, vertex) : no_tet;
    };

    const std::size_t new_size = mesh_.tets.size() + patch.size();
    mesh_.tets.resize(new_size);
    mesh_.kinds.resize(new_size);
    mesh_.neighbours.resize(new_size);
    mesh_.face_tags.resize(new_size);

    for (int i = 0; i < size; ++i) {
      const PatchTet& p = record[i];
      const auto& v = p.v;
      const int type = p.kind.type();
      const int child_type = (type + 1) % 3;
      const TetId c0 = p.slot;
      const TetId c1 = p.child1;

      mesh_.tets[c0] = {v[0], v[2], v[3], m};
      mesh_.kinds[c0] = TetKind::make(child_type, p.kind.negative());
      mesh_.neighbours[c0] = {c1, across(p, 2, v[0]), across(p, 3, v[0]), p.n[1]};
      mesh_.face_tags[c0] = {no_face_tag, p.tags[2], p.tags[3], p.tags[1]};

      if (type == 0) {
        mesh_.tets[c1] = {v[1], v[3], v[2], m};
        mesh_.kinds[c1] = TetKind::make(child_type, p.kind.negative());
        mesh_.neighbours[c1] = {c0, across(p, 3, v[1]), across(p, 2, v[1]), p.n[0]};
        mesh_.face_tags[c1] = {no_face_tag, p.tags[3], p.tags[2], p.tags[0]};
      } else {
        mesh_.tets[c1] = {v[1], v[2], v[3], m};
        mesh_.kinds[c1] = TetKind::make(child_type, !p.kind.negative());
        mesh_.neighbours[c1] = {c0, across(p, 2, v[1]), across(p, 3, v[1]), p.n[0]};
        mesh_.face_tags[c1] = {no_face_tag, p.tags[2], p.tags[3], p.tags[0]};
      }
      // The tet beyond face 0 (opposite v0) now touches child 1; face 1's neighbour keeps child 0 in
      // the parent's slot.
      if (p.n[0] != no_tet) {
        auto& back = mesh_.neighbours[p.n[0]];
        *std::find(back.begin(), back.end(), c0) = c1;
      }
      if (pending_ && c0 < static_cast<TetId>(pending_->size())) (*pending_)[c0] = 0;
    }
    bisections_ += size;
    for (int i = 0; i < size; ++i) {
      if (created_) created_->push_back(record[i].child1);
      if (on_child_) on_child_(record[i].slot, record[i].child1);
    }
  }

  VertexId add_midpoint(VertexId a, VertexId b) {
    const GridPoint& ga = mesh_.grid[a];
    const GridPoint& gb = mesh_.grid[b];
    GridPoint mid{};
    for (int k = 0; k < 3; ++k) {
      if ((ga[k] + gb[k]) % 2 != 0)
        throw MeshingError("refinement depth limit reached: an edge of length 2^-" + std::to_string(grid_bits) +
                           " cells cannot be bisected exactly");
      mid[k] = (ga[k] + gb[k]) / 2;
    }
    return mesh_.add_vertex(0.5 * (mesh_.points[a] + mesh_.points[b]), mid);
  }

  TetMesh& mesh_;
  const ChildCallback& on_child_;
  std::vector<std::uint8_t>* pending_;
  std::vector<TetId>* created_ = nullptr;
  std::int64_t bisections_ = 0;
};

std::int64_t bisect_pending(TetMesh& mesh, std::vector<std::uint8_t>& pending, const ChildCallback& on_child) {
  Bisector bisector(mesh, on_child, &pending);
  for (TetId t = 0; t < static_cast<TetId>(pending.size()); ++t)
    if (pending[t]) bisector.bisect(t);
  return bisector.bisections();
}

}  // namespace

std::int64_t refine_marked(TetMesh& mesh, std::span<const TetId> marked, const ChildCallback& on_child) {
  std::vector<std::uint8_t> pending(mesh.tets.size(), 0);
  for (TetId t : marked) pending[t] = 1;
  return bisect_pending(mesh, pending, on_child);
}

void refine_uniformly(TetMesh& mesh, int levels) {
  for (int level = 0; level < levels; ++level) {
    mesh.reserve_tets(2 * mesh.tets.size());
    std::vector<std::uint8_t> pending(mesh.tets.size(), 1);
    bisect_pending(mesh, pending, {});
  }
}

VertexId split_edge(TetMesh& mesh, TetId start, VertexId a, VertexId b, const ChildCallback& on_child) {
  GridPoint mid{};
  for (int k = 0; k < 3; ++k) mid[k] = (mesh.grid[a][k] + mesh.grid[b][k]) / 2;
  auto contains_edge = [&](TetId t) {
    const auto& v = mesh.tets[t];
    return std::find(v.begin(), v.end(), a) != v.end() && std::find(v.begin(), v.end(), b) != v.end();
  };
  std::vector<TetId> created;
  Bisector bisector(mesh, on_child, nullptr);
  bisector.record_children_in(&created);
  TetId t = start;
  for (;;) {
    const VertexId first_new = mesh.num_vertices();
    created.clear();
    bisector.bisect(t);
    for (VertexId v = first_new; v < mesh.num_vertices(); ++v)
      if (mesh.grid[v] == mid) return v;
    // The edge survives in a descendant of t: in t's slot or in a child appended by this bisection.
    if (!contains_edge(t)) {
      const auto it = std::find_if(created.begin(), created.end(), contains_edge);
      if (it == created.end()) throw MeshingError("split_edge lost track of the edge being split");
      t = *it;
    }
  }
}

}  // namespace meccano
