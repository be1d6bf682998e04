// How the process's heap hands memory back to the system.
#pragma once

namespace arcsim {

// Keeps freed memory in the heap for the next allocation instead of returning it to the system: blocks up to
// 1 GiB come from the heap, not from their own mapping, and the heap's top is never trimmed. WHY: every step
// frees and allocates the same large arrays again (CHOLMOD's factor after each new symbolic analysis, the
// system's blocks after a remesh), and with glibc's defaults (mappings from 128 KiB to 32 MiB, trimming above
// 128 KiB) each one came back as fresh pages that fault on first touch: 8% of flag.json's wall went to page
// faults in CHOLMOD's clearing of its factor (docs/benchmarks.md, "flag.json's page faults and candidate sort").
// The cost is a process that keeps its peak heap (tshirt.json's peak resident set: +5%). Call once, first thing
// in main.
void keep_freed_memory_in_heap();

}  // namespace arcsim
