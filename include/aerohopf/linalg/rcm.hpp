#pragma once
// Reverse Cuthill-McKee ordering of a (block) sparsity graph.
//
// WHY: the fill that an incomplete factorisation keeps and the quality of what it drops both
// depend on the ordering. RCM clusters the non-zeros near the diagonal (small profile), which is
// what the original work used with point-wise ILU (spec 07). The graph is symmetrised (i~j if
// either (i,j) or (j,i) is stored); each connected component starts from a pseudo-peripheral
// node found by repeated breadth-first search (George & Liu), neighbours are visited by
// increasing degree, and the final order is reversed.
//
//   std::vector<int> perm = reverse_cuthill_mckee(row_ptr, col_index);
//   // perm[new] = old;  inverse_permutation(perm)[old] = new
#include <algorithm>
#include <cstddef>
#include <vector>

#include "../error.hpp"

namespace aerohopf {

/// inv[perm[k]] = k; throws input_error if perm is not a permutation.
inline std::vector<int> inverse_permutation(const std::vector<int>& perm) {
  std::vector<int> inv(perm.size(), -1);
  for (std::size_t k = 0; k < perm.size(); ++k) {
    require(perm[k] >= 0 && static_cast<std::size_t>(perm[k]) < perm.size() && inv[perm[k]] < 0,
            "inverse_permutation: entry ", k, " = ", perm[k], " makes it no permutation");
    inv[perm[k]] = static_cast<int>(k);
  }
  return inv;
}

/// RCM order (perm[new] = old) of the square pattern given in compressed rows.
inline std::vector<int> reverse_cuthill_mckee(const std::vector<int>& row_ptr, const std::vector<int>& col_index) {
  const int n = static_cast<int>(row_ptr.size()) - 1;
  require(n >= 0, "reverse_cuthill_mckee: empty row_ptr");
  // symmetrised adjacency without self loops
  std::vector<int> deg(n, 0);
  for (int i = 0; i < n; ++i)
    for (int p = row_ptr[i]; p < row_ptr[i + 1]; ++p) {
      const int j = col_index[p];
      require(j >= 0 && j < n, "reverse_cuthill_mckee: column ", j, " in row ", i, " outside ", n);
      if (j != i) {
        ++deg[i];
        ++deg[j];
      }
    }
  std::vector<int> adj_ptr(n + 1, 0);
  for (int i = 0; i < n; ++i) adj_ptr[i + 1] = adj_ptr[i] + deg[i];
  std::vector<int> adj(adj_ptr[n]), fill(adj_ptr.begin(), adj_ptr.end() - 1);
  for (int i = 0; i < n; ++i)
    for (int p = row_ptr[i]; p < row_ptr[i + 1]; ++p) {
      const int j = col_index[p];
      if (j != i) {
        adj[fill[i]++] = j;
        adj[fill[j]++] = i;
      }
    }
  for (int i = 0; i < n; ++i) {  // merge duplicates (i,j) and (j,i) both stored
    auto first = adj.begin() + adj_ptr[i], last = adj.begin() + fill[i];
    std::sort(first, last);
    deg[i] = static_cast<int>(std::unique(first, last) - first);
  }

  std::vector<int> order;
  order.reserve(n);
  // BFS from root over unvisited nodes of its component; returns the last level's nodes' start
  auto bfs = [&](int root, std::vector<int>& out, std::vector<int>& lev) {
    out.clear();
    out.push_back(root);
    lev[root] = 0;
    for (std::size_t h = 0; h < out.size(); ++h) {
      const int v = out[h];
      for (int p = adj_ptr[v]; p < adj_ptr[v] + deg[v]; ++p)
        if (lev[adj[p]] < 0) {
          lev[adj[p]] = lev[v] + 1;
          out.push_back(adj[p]);
        }
    }
  };
  std::vector<char> placed(n, 0);
  std::vector<int> comp, lev(n, -1), nbrs;
  for (int start = 0; start < n; ++start) {
    if (placed[start]) continue;
    // pseudo-peripheral root: move to a minimum-degree node of the last BFS level while the
    // eccentricity grows
    int root = start, ecc = -1;
    for (int sweep = 0; sweep < 8; ++sweep) {
      bfs(root, comp, lev);
      const int e = lev[comp.back()];
      int best = comp.back();
      for (int v : comp)
        if (lev[v] == e && deg[v] < deg[best]) best = v;
      for (int v : comp) lev[v] = -1;
      if (e <= ecc) break;
      ecc = e;
      root = best;
    }
    // Cuthill-McKee from root: neighbours by increasing degree
    const std::size_t first = order.size();
    order.push_back(root);
    placed[root] = 1;
    for (std::size_t h = first; h < order.size(); ++h) {
      const int v = order[h];
      nbrs.clear();
      for (int p = adj_ptr[v]; p < adj_ptr[v] + deg[v]; ++p)
        if (!placed[adj[p]]) {
          placed[adj[p]] = 1;
          nbrs.push_back(adj[p]);
        }
      std::sort(nbrs.begin(), nbrs.end(), [&](int a, int b) { return deg[a] < deg[b] || (deg[a] == deg[b] && a < b); });
      order.insert(order.end(), nbrs.begin(), nbrs.end());
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

/// Bandwidth max |i - j| over stored (i, j) after renumbering old -> inv[old] (inv empty: none).
inline int pattern_bandwidth(const std::vector<int>& row_ptr, const std::vector<int>& col_index,
                             const std::vector<int>& inv = {}) {
  int bw = 0;
  const int n = static_cast<int>(row_ptr.size()) - 1;
  for (int i = 0; i < n; ++i)
    for (int p = row_ptr[i]; p < row_ptr[i + 1]; ++p) {
      const int a = inv.empty() ? i : inv[i], b = inv.empty() ? col_index[p] : inv[col_index[p]];
      bw = std::max(bw, a > b ? a - b : b - a);
    }
  return bw;
}

}  // namespace aerohopf
