// How the real pager (memory/file_pager.hpp) makes a resident page appear at its address:
// the memory.page_mapping key's values, apart so that plans name one without the pager.
#pragma once

namespace wavetrace {

// How a resident page appears at its address.
// - userfaultfd: the range is one anonymous read-only mapping registered for missing-page
//   faults, which the kernel raises as SIGBUS in the reading thread (UFFD_FEATURE_SIGBUS). A
//   page comes in by one copy from the read's buffer (UFFDIO_COPY) and leaves by
//   MADV_DONTNEED: two system calls a read, and no change to the process's mappings (which
//   take the address space's lock for writing, against every thread's faults).
// - memfd: the range is PROT_NONE; a page is written into a slot of a memfd pool and mapped
//   over its place (a mapping a resident page; faults are SIGSEGV), and an evicted page's
//   place is reserved again: four system calls a read, two of them mmap.
// - automatic: userfaultfd where the kernel allows this process to use it (root, or
//   vm.unprivileged_userfaultfd = 1; container sandboxes often forbid it), memfd elsewhere.
enum class PageMapping { automatic, userfaultfd, memfd };
constexpr const char* to_string(PageMapping mapping) {
  switch (mapping) {
    case PageMapping::automatic: return "auto";
    case PageMapping::userfaultfd: return "userfaultfd";
    case PageMapping::memfd: return "memfd";
  }
  return "?";
}

}  // namespace wavetrace
