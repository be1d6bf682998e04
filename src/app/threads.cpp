#include "app/threads.hpp"

#include <omp.h>

namespace arcsim {

void configure_threads(int threads) {
  if (threads > 0) {
    omp_set_dynamic(0);
    omp_set_num_threads(threads);
  } else {
    omp_set_dynamic(1);
  }
}

}  // namespace arcsim
