// What placing a 64 KiB page costs on this machine, apart from its read: the real pager's two
// ways (wavetrace/memory/file_pager.hpp), over 4,096 pages, four rounds. userfaultfd: one
// UFFDIO_COPY a page, MADV_DONTNEED for all; memfd: a pwrite into the pool's slot, an mmap
// with MAP_POPULATE at the page's place, the place reserved again. Then the first and the
// second read of each 4 KiB of the placed pages: in a virtual machine whose hypervisor keeps
// shadow page tables, the first read of a newly mapped 4 KiB costs an exit.
//   gcc -O2 bench/page_placement.c -o /tmp/page_placement && taskset -c 0 /tmp/page_placement
#define _GNU_SOURCE
#include <fcntl.h>
#include <linux/userfaultfd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

enum { kPage = 65536, kPages = 4096, kRounds = 4 };

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static volatile long sink;

// Reads one byte of each 4 KiB of the range, returns the seconds taken.
static double read_all(const char* base) {
  const double start = now();
  long sum = 0;
  for (size_t i = 0; i < (size_t)kPages * kPage; i += 4096) sum += base[i];
  sink += sum;
  return now() - start;
}

int main(void) {
  char* source = aligned_alloc(4096, kPage);
  memset(source, 1, kPage);
  const size_t bytes = (size_t)kPages * kPage;
  for (int mode = 0; mode < 2; ++mode) {
    char* base = mmap(NULL, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    int fault_fd = -1, pool_fd = -1;
    if (mode == 0) {
      fault_fd = (int)syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK);
      struct uffdio_api api = {.api = UFFD_API, .features = UFFD_FEATURE_SIGBUS};
      struct uffdio_register range = {.range = {(unsigned long)base, bytes}, .mode = UFFDIO_REGISTER_MODE_MISSING};
      if (fault_fd < 0 || ioctl(fault_fd, UFFDIO_API, &api) || mprotect(base, bytes, PROT_READ) ||
          madvise(base, bytes, MADV_NOHUGEPAGE) || ioctl(fault_fd, UFFDIO_REGISTER, &range)) {
        perror("userfaultfd");
        continue;
      }
    } else {
      pool_fd = memfd_create("pool", MFD_CLOEXEC);
      if (pool_fd < 0 || ftruncate(pool_fd, bytes)) {
        perror("memfd");
        return 1;
      }
    }
    double place = 0, first = 0, second = 0, evict = 0;
    for (int round = 0; round < kRounds; ++round) {
      double start = now();
      for (size_t i = 0; i < kPages; ++i) {
        char* at = base + i * kPage;
        if (mode == 0) {
          struct uffdio_copy copy = {.dst = (unsigned long)at, .src = (unsigned long)source, .len = kPage};
          if (ioctl(fault_fd, UFFDIO_COPY, &copy)) return perror("UFFDIO_COPY"), 1;
        } else if (pwrite(pool_fd, source, kPage, (off_t)(i * kPage)) != kPage ||
                   mmap(at, kPage, PROT_READ, MAP_SHARED | MAP_FIXED | MAP_POPULATE, pool_fd, (off_t)(i * kPage)) == MAP_FAILED) {
          return perror("memfd placing"), 1;
        }
      }
      place += now() - start;
      first += read_all(base);
      second += read_all(base);
      start = now();
      if (mode == 0) {
        madvise(base, bytes, MADV_DONTNEED);
      } else {
        for (size_t i = 0; i < kPages; ++i) {
          mmap(base + i * kPage, kPage, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE | MAP_FIXED, -1, 0);
        }
      }
      evict += now() - start;
    }
    const double per_page = 1e6 / ((double)kPages * kRounds);
    printf("%-11s per 64 KiB page: placing %.1f us, first read of its 16 4 KiB %.1f us, second %.2f us, evicting %.2f us\n",
           mode == 0 ? "userfaultfd" : "memfd", place * per_page, first * per_page, second * per_page, evict * per_page);
    munmap(base, bytes);
    if (fault_fd >= 0) close(fault_fd);
    if (pool_fd >= 0) close(pool_fd);
  }
  return 0;
}
