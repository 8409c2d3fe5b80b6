// The converged double-precision reference over a list of directions, for
// the tests that hold the GPU to it (accuracy_test, hard_cases_test).
#pragma once

#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "skybake/tools/accuracy.h"

namespace skybake::testing {

// The converged reference's radiance along each of `dirs`, on two threads.
inline std::vector<glm::dvec3> ReferenceRadiances(const ConvergedReference& ref, const std::vector<glm::dvec3>& dirs,
                                                  const glm::dvec3& sun) {
  std::vector<glm::dvec3> expected(dirs.size());
  std::vector<std::thread> pool;
  for (size_t t = 0; t < 2; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t; i < dirs.size(); i += 2) expected[i] = ref.Radiance(dirs[i], sun);
    });
  for (std::thread& th : pool) th.join();
  return expected;
}

}  // namespace skybake::testing
