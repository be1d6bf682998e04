#include "app/heap.hpp"

#include <malloc.h>

#include <climits>

namespace arcsim {

void keep_freed_memory_in_heap() {
  // Fixed values also turn off glibc's sliding threshold, which followed the largest freed mapping up to 32 MiB.
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

}  // namespace arcsim
