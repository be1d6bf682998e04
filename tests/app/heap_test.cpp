// keep_freed_memory_in_heap (app/heap.hpp): a large block comes from the heap, not from a mapping of its own,
// and freeing it leaves the heap's pages in the process for the next one.
#include "app/heap.hpp"

#include <gtest/gtest.h>

#include <malloc.h>

#include <cstdlib>
#include <cstring>

namespace arcsim {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kGlibcMalloc = false;  // AddressSanitizer replaces malloc: mallinfo2 describes nothing of it
#else
constexpr bool kGlibcMalloc = true;
#endif

TEST(KeepFreedMemoryInHeap, ALargeBlockComesFromTheHeapAndItsPagesStayAfterItIsFreed) {
  if (!kGlibcMalloc) GTEST_SKIP() << "malloc is not glibc's under AddressSanitizer";
  keep_freed_memory_in_heap();
  // 48 MiB: above glibc's default ceiling for its sliding mapping threshold (32 MiB), so with the defaults this
  // block would always be a mapping of its own, returned to the system by free.
  const size_t size = size_t(48) << 20;
  const struct mallinfo2 before = mallinfo2();
  void* block = std::malloc(size);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, size);
  const struct mallinfo2 held = mallinfo2();
  EXPECT_EQ(held.hblks, before.hblks) << "the block was mapped on its own";
  EXPECT_GE(held.arena, before.arena + size) << "the heap did not grow by the block";
  std::free(block);
  const struct mallinfo2 after = mallinfo2();
  EXPECT_GE(after.arena, before.arena + size) << "the heap was trimmed: the block's pages went back to the system";
  EXPECT_GE(after.fordblks, size) << "the freed block is not free space of the heap";
}

}  // namespace
}  // namespace arcsim
