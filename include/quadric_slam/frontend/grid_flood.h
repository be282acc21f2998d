// Breadth-first flood fill over the 4-neighbourhood of an organized cloud's pixel grid: the walk
// that region growing, region filling and connected components share. What joins is the
// caller's decision (normals, distances, depth jumps), given as a predicate.
#pragma once

#include <cstddef>
#include <vector>

namespace quadric_slam {

// `frontier` holds the pixels to expand (row-major indices of a width x height grid; the seeds at
// first). Each 4-neighbour j of an expanded pixel i is offered to admit(i, j); when admit returns
// true, j joins: it is appended to frontier and expanded in turn. admit must itself mark what it
// admits (or what it rejects for good), or a pixel may be offered and join twice. On return
// frontier holds the seeds followed by every pixel that joined, in the order they joined.
template <typename Admit>
void floodFill4(int width, int height, std::vector<int>& frontier, Admit&& admit) {
  for (std::size_t head = 0; head < frontier.size(); ++head) {
    const int i = frontier[head];
    const int u = i % width, v = i / width;
    const int neighbours[4] = {u > 0 ? i - 1 : -1, u + 1 < width ? i + 1 : -1,
                               v > 0 ? i - width : -1, v + 1 < height ? i + width : -1};
    for (int j : neighbours)
      if (j >= 0 && admit(i, j))
        frontier.push_back(j);
  }
}

}  // namespace quadric_slam
