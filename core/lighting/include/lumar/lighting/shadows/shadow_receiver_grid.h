#pragma once
// Receiver points sorted for culling: split into nearly flat groups (a floor, a table
// top), each with a uniform grid of square buckets over its plane. A shadow cone's
// footprint on a group's plane is then a few runs of buckets per row, and each run is a
// contiguous range of receivers in `order`.
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace lumar {

struct ReceiverGrid {
  // A point x lies at (u, v, h) = (dot(x - origin, u_axis), dot(x - origin, v_axis),
  // dot(x - origin, normal)); every receiver of the group has h in [h_min, h_max].
  glm::vec3 origin{0.0f}, u_axis{1, 0, 0}, v_axis{0, 0, 1}, normal{0, 1, 0};
  float h_min = 0.0f, h_max = 0.0f;
  float u0 = 0.0f, v0 = 0.0f, cell = 1.0f;  // bucket (i, j) covers u0 + [i, i+1) cell, v0 + [j, j+1) cell
  int nu = 1, nv = 1;
  std::uint32_t first_bucket = 0;  // bucket (i, j) is ReceiverGrids::bucket_first[first_bucket + j * nu + i]
};

struct ReceiverGrids {
  std::vector<ReceiverGrid> grids;
  std::vector<std::uint32_t> order;         // receiver indices: grid by grid, row (j) by row, bucket (i) by bucket
  std::vector<std::uint32_t> bucket_first;  // bucket b holds order[bucket_first[b], bucket_first[b + 1])
};

// Groups are split across their mean normal (at the middle of their extent along it)
// until that extent is at most `flatness` x their longest side; buckets are about two
// receiver spacings wide. `normals`: the points' unit surface normals.
ReceiverGrids build_receiver_grids(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& normals,
                                   float flatness = 0.02f);

}  // namespace lumar
