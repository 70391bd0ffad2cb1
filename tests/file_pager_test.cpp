// The real pager on a small file of numbered 4 KiB pages, with each way of placing pages
// (userfaultfd and memfd): the bytes it shows, its LRU eviction, faults counted by part,
// resident memory, and a file cut short while it is paged.
#include <gtest/gtest.h>

#include <atomic>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/memory/page_trace.hpp"

namespace wavetrace {
namespace {

constexpr std::size_t kPage = 4096;
constexpr std::size_t kPages = 16;

// Every 32-bit word of page p holds p * 1000 + its index in the page.
std::string numbered_file(const std::string& name, std::size_t pages = kPages) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "wavetrace_tests";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (std::to_string(::getpid()) + "_" + name)).string();
  std::vector<std::uint32_t> words(pages * kPage / 4);
  for (std::size_t i = 0; i < words.size(); ++i) words[i] = std::uint32_t(i / (kPage / 4) * 1000 + i % (kPage / 4));
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * 4));
  return path;
}

std::uint32_t word(const FilePager& pager, std::size_t page, std::size_t index) {
  return reinterpret_cast<const volatile std::uint32_t*>(pager.base() + page * kPage)[index];
}

// userfaultfd where this kernel lets the process use it: a test of that mapping is skipped,
// saying why, where it does not (memfd is tested everywhere).
class FilePagerTest : public ::testing::TestWithParam<PageMapping> {
 protected:
  void SetUp() override {
    if (GetParam() != PageMapping::userfaultfd) return;
    const std::string path = numbered_file("pager_probe.bin", 1);
    try {
      FilePager probe(path, kPage, kPage, kPage, 1, PageMapping::userfaultfd);
    } catch (const std::runtime_error& refused) {
      std::filesystem::remove(path);
      GTEST_SKIP() << refused.what();
    }
    std::filesystem::remove(path);
  }
};
class FilePagerDeathTest : public FilePagerTest {};

std::string mapping_name(const ::testing::TestParamInfo<PageMapping>& info) { return to_string(info.param); }
INSTANTIATE_TEST_SUITE_P(Mappings, FilePagerTest, ::testing::Values(PageMapping::userfaultfd, PageMapping::memfd),
                         mapping_name);
INSTANTIATE_TEST_SUITE_P(Mappings, FilePagerDeathTest, ::testing::Values(PageMapping::userfaultfd, PageMapping::memfd),
                         mapping_name);

TEST_P(FilePagerTest, PlacesPagesAsAsked) {
  const std::string path = numbered_file("pager_mapping.bin");
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 1, GetParam());
  EXPECT_EQ(pager.mapping(), GetParam());
  EXPECT_EQ(word(pager, 5, 1), 5001u);
  FilePager automatic(path, kPages * kPage, kPage, 4 * kPage, 1);
  EXPECT_NE(automatic.mapping(), PageMapping::automatic);
  EXPECT_EQ(word(automatic, 6, 2), 6002u);
  std::filesystem::remove(path);
}

// A memfd pool maps each resident page on its own, under the kernel's limit on mappings; a
// userfaultfd range is one mapping whatever the pool holds. (Nothing is read: the file's
// size only sets the range.)
TEST_P(FilePagerTest, HoldsMoreThan30000PagesOnlyWithUserfaultfd) {
  const std::string path = numbered_file("pager_many.bin");
  constexpr std::size_t kManyPages = 40000, kManySlots = 30001;
  if (GetParam() == PageMapping::memfd) {
    try {
      FilePager pager(path, kManyPages * kPage, kPage, kManySlots * kPage, 1, GetParam());
      ADD_FAILURE() << "a memfd pool of 30,001 pages was made";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("memory.page_bytes"), std::string::npos) << error.what();
    }
  } else {
    FilePager pager(path, kManyPages * kPage, kPage, kManySlots * kPage, 1, GetParam());
    EXPECT_EQ(pager.budget_bytes(), kManySlots * kPage);
    EXPECT_EQ(word(pager, 7, 0), 7000u);
  }
  std::filesystem::remove(path);
}

TEST_P(FilePagerTest, ShowsTheFileAndEvictsTheLeastRecentlyUsedPage) {
  const std::string path = numbered_file("pager_lru.bin");
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 1, GetParam());
  for (std::size_t page : {0, 1, 2, 3}) pager.touch(pager.base() + page * kPage);
  EXPECT_EQ(pager.total().faults, 4u);
  EXPECT_EQ(pager.total().unannounced, 0u);
  pager.touch(pager.base());             // page 0 becomes the most recent: page 1 is now the oldest
  pager.touch(pager.base() + 4 * kPage);  // evicts page 1
  EXPECT_EQ(pager.total().faults, 5u);
  pager.touch(pager.base());  // still resident
  EXPECT_EQ(pager.total().faults, 5u);
  EXPECT_EQ(word(pager, 1, 7), 1007u);  // unannounced read of the evicted page: faults and loads it
  EXPECT_EQ(pager.total().faults, 6u);
  EXPECT_EQ(pager.total().unannounced, 1u);
  for (std::size_t page = 0; page < kPages; ++page) EXPECT_EQ(word(pager, page, 100), page * 1000 + 100) << page;
}

// A probe numbers a read's page by its address alone (address >> log2(page_bytes)): that is
// the pager's page only where the file's range starts on a page boundary. Pages larger than
// the kernel's are not aligned by mmap itself.
TEST_P(FilePagerTest, StartsTheFileOnAPageBoundary) {
  const std::string path = numbered_file("pager_aligned.bin");
  for (const std::size_t page_bytes : {kPage, std::size_t{1} << 16, std::size_t{1} << 20, std::size_t{1} << 22}) {
    std::vector<std::unique_ptr<FilePager>> pagers;  // held together, so that each is placed anew
    for (int copy = 0; copy < 4; ++copy) {
      pagers.push_back(std::make_unique<FilePager>(path, kPages * kPage, page_bytes, 2 * page_bytes, 1, GetParam()));
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pagers.back()->base()) % page_bytes, 0u) << page_bytes;
      EXPECT_EQ(word(*pagers.back(), kPages - 1, 3), (kPages - 1) * 1000 + 3);  // the last page, by a fault
    }
  }
  std::filesystem::remove(path);
}

// A read across a page boundary needs both pages at once: a pool of one page would evict
// each half for the other for ever, so a budget under two pages is refused, naming the key,
// unless the file is one page.
TEST_P(FilePagerTest, RefusesAPoolOfOnePageForAFileOfMore) {
  const std::string path = numbered_file("pager_one_slot.bin");
  try {
    FilePager pager(path, kPages * kPage, kPage, kPage + kPage / 2, 1, GetParam());
    ADD_FAILURE() << "a pool of one page was made for a file of " << kPages;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("memory.budget (6144 bytes) holds fewer than two pages"), std::string::npos)
        << error.what();
  }
  FilePager one_page(path, kPage, kPage, kPage, 1, GetParam());  // a file of one page: one slot is enough
  EXPECT_EQ(word(one_page, 0, 9), 9u);
  FilePager two_pages(path, kPages * kPage, kPage, 2 * kPage, 1, GetParam());
  EXPECT_EQ(word(two_pages, 3, 9), 3009u);
  std::filesystem::remove(path);
}

// memory.page_trace: every touch, in order, as the page numbers the file holds; reads the
// probes did not announce (faults) are not touches.
TEST_P(FilePagerTest, RecordsEveryTouchInOrderWhenTraced) {
  const std::string path = numbered_file("pager_trace.bin");
  const std::string trace_path = path + ".pages";
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 1, GetParam());
  {
    PageTrace trace(trace_path);
    pager.set_page_trace(&trace);
    for (std::size_t page : {3, 1, 3, 7, 15}) pager.touch(pager.base() + page * kPage + 8);
    EXPECT_EQ(word(pager, 9, 0), 9000u);  // a fault, not a touch
    pager.set_page_trace(nullptr);
    pager.touch(pager.base());  // after the trace is detached
    EXPECT_EQ(trace.recorded(), 5u);
  }
  std::ifstream in(trace_path, std::ios::binary);
  std::vector<std::uint32_t> pages(8);
  in.read(reinterpret_cast<char*>(pages.data()), std::streamsize(pages.size() * 4));
  pages.resize(std::size_t(in.gcount()) / 4);
  EXPECT_EQ(pages, (std::vector<std::uint32_t>{3, 1, 3, 7, 15}));
  EXPECT_THROW(PageTrace("/nonexistent_dir/x.pages"), std::runtime_error);
  if (std::filesystem::exists("/dev/full")) {  // a full disk: an error naming the file
    PageTrace full("/dev/full");
    full.record(1);
    try {
      full.flush();
      FAIL() << "a write to /dev/full succeeded";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("writing '/dev/full' failed"), std::string::npos) << error.what();
    }
  }
  std::filesystem::remove(trace_path);
}

// A full pool of 16 slots evicts its two least recently used pages at once (an eighth of
// it): one TLB flush for both.
TEST_P(FilePagerTest, AFullPoolEvictsAGroupOfTheLeastRecentlyUsedPages) {
  const std::string path = numbered_file("pager_group.bin", 32);
  FilePager pager(path, 32 * kPage, kPage, 16 * kPage, 1, GetParam());
  for (std::size_t page = 0; page < 16; ++page) pager.touch(pager.base() + page * kPage);
  pager.touch(pager.base() + 16 * kPage);  // evicts pages 0 and 1
  EXPECT_EQ(pager.total().faults, 17u);
  pager.touch(pager.base() + 17 * kPage);  // takes the second freed slot: no eviction
  pager.touch(pager.base() + 2 * kPage);   // still resident
  EXPECT_EQ(pager.total().faults, 18u);
  EXPECT_EQ(word(pager, 1, 3), 1003u);  // evicted with page 0: faults and loads it (evicting 3 and 4)
  EXPECT_EQ(pager.total().faults, 19u);
  pager.touch(pager.base() + 5 * kPage);  // still resident
  EXPECT_EQ(pager.total().faults, 19u);
  EXPECT_EQ(word(pager, 4, 9), 4009u);
  EXPECT_EQ(pager.total().faults, 20u);
  for (std::size_t page = 0; page < 32; ++page) EXPECT_EQ(word(pager, page, 100), page * 1000 + 100) << page;
}

// Resident kilobytes of this process's mappings that `counted` picks by their smaps header
// line ("start-end perms offset dev inode name").
template <typename Pick>
std::size_t resident_kb(Pick counted) {
  std::ifstream smaps("/proc/self/smaps");
  std::size_t kb = 0;
  bool picked = false;
  for (std::string line; std::getline(smaps, line);) {
    if (!line.empty() && std::isxdigit(static_cast<unsigned char>(line[0])) && line.find('-') < line.find(' ')) {
      picked = counted(line);
    } else if (picked && line.starts_with("Rss:")) {
      kb += std::stoul(line.substr(4));
    }
  }
  return kb;
}
std::size_t pool_resident_kb() {
  return resident_kb([](const std::string& line) { return line.find("wavetrace-page-pool") != std::string::npos; });
}
// The mappings inside [begin, end): the pager's range.
std::size_t range_resident_kb(const std::byte* begin, const std::byte* end) {
  return resident_kb([&](const std::string& line) {
    const auto start = std::stoull(line.substr(0, line.find('-')), nullptr, 16);
    return start >= reinterpret_cast<std::uintptr_t>(begin) && start < reinterpret_cast<std::uintptr_t>(end);
  });
}

// A page read into the pool is mapped once, at its place: through a writable view of the
// pool as well, it counted twice in the process's resident memory (a 12 GB pool read 24 GB).
TEST_P(FilePagerTest, ResidentMemoryCountsAPagedPageOnce) {
  constexpr std::size_t kFilePages = 256, kSlots = 64;
  const std::string path = numbered_file("pager_resident.bin", kFilePages);
  FilePager pager(path, kFilePages * kPage, kPage, kSlots * kPage, 1, GetParam());
  for (std::size_t pass = 0; pass < 2; ++pass) {
    for (std::size_t page = 0; page < kFilePages; ++page) ASSERT_EQ(word(pager, page, 3), page * 1000 + 3);
  }
  EXPECT_EQ(range_resident_kb(pager.base(), pager.base() + kFilePages * kPage), kSlots * kPage / 1024);
  // The pool is mapped nowhere else (memfd), or there is none (userfaultfd).
  EXPECT_EQ(pool_resident_kb(), GetParam() == PageMapping::memfd ? kSlots * kPage / 1024 : 0);
  std::filesystem::remove(path);
}

TEST_P(FilePagerTest, CountsFaultsByPartOfTheFile) {
  const std::string path = numbered_file("pager_parts.bin");
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 2, GetParam());
  pager.name_parts({"nodes", "leaves"}, {{8 * kPage, 4 * kPage, 1}, {0, 8 * kPage, 0}});
  ASSERT_EQ(pager.part_names(), (std::vector<std::string>{"nodes", "leaves", "other"}));
  {
    const FilePager::ClientScope scope(1);
    pager.touch(pager.base() + 1 * kPage);
    pager.touch(pager.base() + 2 * kPage + 100);
    pager.touch(pager.base() + 9 * kPage);
  }
  EXPECT_EQ(word(pager, 14, 0), 14000u);  // a fault outside any client and any part
  EXPECT_EQ(pager.faults_by_part(1), (std::vector<std::uint64_t>{2, 1, 0}));
  EXPECT_EQ(pager.faults_by_part(2), (std::vector<std::uint64_t>{0, 0, 1}));
  EXPECT_EQ(pager.faults_by_part(FilePager::kAllClients), (std::vector<std::uint64_t>{2, 1, 1}));
  pager.reset();
  EXPECT_EQ(pager.faults_by_part(FilePager::kAllClients), (std::vector<std::uint64_t>{0, 0, 0}));
}

// Pages the prefetch client loads are prefetched; the first read of one by another client
// before its eviction is a hit, later reads and reads after the eviction are not.
TEST_P(FilePagerTest, CountsAPrefetchedPageReadByAnotherClientAsAHit) {
  const std::string path = numbered_file("pager_prefetch.bin");
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 2, GetParam());
  pager.set_prefetch_client(1);
  {
    const FilePager::ClientScope prefetcher(1);
    for (std::size_t page : {0, 1, 2}) pager.touch(pager.base() + page * kPage);
  }
  EXPECT_EQ(pager.counters(1).faults, 3u);
  const FilePager::ClientScope reader(0);
  pager.touch(pager.base());
  pager.touch(pager.base() + 100);
  EXPECT_EQ(word(pager, 1, 5), 1005u);  // resident: no fault, and a read the pager hears of only through touch
  pager.touch(pager.base() + 1 * kPage);
  EXPECT_EQ(pager.prefetch_hits(), 2u);
  EXPECT_EQ(pager.counters(0).faults, 0u);
  for (std::size_t page : {3, 4, 5, 6}) pager.touch(pager.base() + page * kPage);  // evicts 0, 1 and 2
  pager.touch(pager.base() + 2 * kPage);  // read again, but by the reader: no hit
  EXPECT_EQ(pager.prefetch_hits(), 2u);
  EXPECT_EQ(pager.counters(0).faults, 5u);
  pager.reset();
  EXPECT_EQ(pager.prefetch_hits(), 0u);
}

// Frames (FilePager::use_frames): pages of 32 KiB, eight 4 KiB blocks of the numbered file each.
constexpr std::size_t kFramePage = 32 * 1024, kBlocksPerFramePage = kFramePage / kPage;
// Eleven pages of budget: two for the mapped pool, nine of 32 KiB as eight frames of 36 KiB.
constexpr std::size_t kFrameBudget = 11 * kFramePage, kFrames = 8;

// Every word a frame shows for `page`, the tail's included, is the file's.
bool frame_shows_page(const std::byte* frame, std::size_t page, std::size_t file_blocks) {
  const auto* words = reinterpret_cast<const std::uint32_t*>(frame);
  for (std::size_t b = 0; b < kBlocksPerFramePage + FilePager::kFrameTailBytes / kPage; ++b) {
    const std::size_t block = page * kBlocksPerFramePage + b;
    for (std::size_t i = 0; i < kPage / 4; i += 97) {
      const std::uint32_t expected = block < file_blocks ? std::uint32_t(block * 1000 + i) : 0u;  // zero past the end
      if (words[b * kPage / 4 + i] != expected) return false;
    }
  }
  return true;
}

TEST_P(FilePagerTest, FramesShowEachPageAndTheFilesNextBytes) {
  constexpr std::size_t kBlocks = 16 * kBlocksPerFramePage;
  const std::string path = numbered_file("pager_frames.bin", kBlocks);
  FilePager pager(path, kBlocks * kPage, kFramePage, kFrameBudget, 1, GetParam());
  EXPECT_FALSE(pager.framed());
  ASSERT_TRUE(pager.use_frames(true));
  EXPECT_EQ(pager.frame_count(), kFrames);
  EXPECT_EQ(pager.budget_bytes(), kFrameBudget);
  for (std::size_t page = 0; page < 16; ++page) {
    std::uint32_t frame = 0;
    const std::byte* shown = pager.pin(pager.base() + page * kFramePage + 100, frame);
    ASSERT_NE(shown, nullptr) << page;
    EXPECT_TRUE(frame_shows_page(shown, page, kBlocks)) << page;  // the last page's tail: zeros
    pager.unpin(frame);
  }
  EXPECT_EQ(pager.total().faults, 16u);
  EXPECT_EQ(pager.total().unannounced, 0u);
  // A read through the file's range still shows the file, from the mapped pool.
  EXPECT_EQ(word(pager, 3 * kBlocksPerFramePage + 2, 5), (3 * kBlocksPerFramePage + 2) * 1000 + 5);
  std::uint32_t frame = 0;
  EXPECT_EQ(pager.pin(&frame, frame), nullptr);  // not the file's
  // Switching needs an empty pool; switched off, the whole budget maps pages again.
  EXPECT_THROW(pager.use_frames(false), std::logic_error);
  pager.reset();
  EXPECT_FALSE(pager.use_frames(false));
  EXPECT_FALSE(pager.framed());
  EXPECT_EQ(pager.pin(pager.base(), frame), nullptr);
  std::filesystem::remove(path);
}

TEST_P(FilePagerTest, FramesAreRefusedForSmallPagesOrFewFrames) {
  const std::string path = numbered_file("pager_frames_small.bin", 64);
  FilePager small_pages(path, 64 * kPage, kPage, 32 * kPage, 1, GetParam());
  EXPECT_FALSE(small_pages.use_frames(true));
  FilePager few(path, 64 * kPage, kFramePage, kFrameBudget - kFramePage, 1, GetParam());
  EXPECT_FALSE(few.use_frames(true));
  EXPECT_EQ(word(few, 9, 3), 9003u);
  std::filesystem::remove(path);
}

TEST_P(FilePagerTest, AFrameLeavesLeastRecentlyUsedButNeverWhilePinned) {
  constexpr std::size_t kBlocks = 32 * kBlocksPerFramePage;
  const std::string path = numbered_file("pager_frames_lru.bin", kBlocks);
  FilePager pager(path, kBlocks * kPage, kFramePage, kFrameBudget, 1, GetParam());
  ASSERT_TRUE(pager.use_frames(true));
  std::uint32_t held = 0;
  const std::byte* page0 = pager.pin(pager.base(), held);  // pinned throughout
  ASSERT_NE(page0, nullptr);
  for (std::size_t page = 1; page < 20; ++page) {  // more than the frames: page 0 would be evicted first
    std::uint32_t frame = 0;
    ASSERT_NE(pager.pin(pager.base() + page * kFramePage, frame), nullptr) << page;
    pager.unpin(frame);
  }
  EXPECT_EQ(pager.total().faults, 20u);
  EXPECT_TRUE(frame_shows_page(page0, 0, kBlocks));
  std::uint32_t again = 0;
  EXPECT_EQ(pager.pin(pager.base() + 7, again), page0);  // still resident, in the same frame
  EXPECT_EQ(again, held);
  EXPECT_EQ(pager.total().faults, 20u);
  pager.unpin(again);
  // Every frame pinned: no frame for another page, until one is let go.
  std::vector<std::uint32_t> pinned = {held};
  for (std::size_t page = 20; pinned.size() < kFrames; ++page) {
    std::uint32_t frame = 0;
    ASSERT_NE(pager.pin(pager.base() + page * kFramePage, frame), nullptr) << page;
    pinned.push_back(frame);
  }
  std::uint32_t none = 0;
  EXPECT_EQ(pager.pin(pager.base() + 30 * kFramePage, none), nullptr);
  pager.unpin(pinned.back());
  const std::byte* freed = pager.pin(pager.base() + 30 * kFramePage, none);
  ASSERT_NE(freed, nullptr);
  EXPECT_TRUE(frame_shows_page(freed, 30, kBlocks));
  pager.unpin(none);
  for (std::size_t k = 0; k + 1 < pinned.size(); ++k) pager.unpin(pinned[k]);
  std::filesystem::remove(path);
}

// Readers on four threads pinning, reading and letting go of pages at random in a pool of
// eight frames: every word each one reads is the file's, whatever the evictions around it.
TEST_P(FilePagerTest, FramesShowTheFileToManyReadersAtOnce) {
  constexpr std::size_t kPagesInFile = 48, kBlocks = kPagesInFile * kBlocksPerFramePage;
  const std::string path = numbered_file("pager_frames_threads.bin", kBlocks);
  FilePager pager(path, kBlocks * kPage, kFramePage, kFrameBudget, 1, GetParam());
  ASSERT_TRUE(pager.use_frames(true));
  std::atomic<std::size_t> wrong{0}, read{0};
  std::vector<std::thread> readers;
  for (unsigned t = 0; t < 4; ++t) {
    readers.emplace_back([&, t] {
      std::mt19937 random(t);
      for (int round = 0; round < 400; ++round) {
        std::uint32_t frames[2];
        const std::size_t pages[2] = {random() % kPagesInFile, random() % kPagesInFile};
        const std::byte* shown[2];
        for (int k = 0; k < 2; ++k) shown[k] = pager.pin(pager.base() + pages[k] * kFramePage, frames[k]);
        for (int k = 0; k < 2; ++k) {
          if (shown[k] == nullptr) continue;  // every frame pinned or being read at that moment
          read.fetch_add(1);
          if (!frame_shows_page(shown[k], pages[k], kBlocks)) wrong.fetch_add(1);
        }
        for (int k = 0; k < 2; ++k) {
          if (shown[k] != nullptr) pager.unpin(frames[k]);
        }
      }
    });
  }
  for (std::thread& reader : readers) reader.join();
  EXPECT_EQ(wrong.load(), 0u);
  EXPECT_GT(read.load(), 3000u);
  EXPECT_GT(pager.total().faults, 100u);
  std::filesystem::remove(path);
}

// A read into a frame that finds the file cut short: an exception naming the file, and the
// frame free again for the pages that are still there.
TEST_P(FilePagerTest, AFileCutShortWhileReadIntoFramesIsAClearErrorNamingIt) {
  constexpr std::size_t kBlocks = 32 * kBlocksPerFramePage;
  const std::string path = numbered_file("pager_frames_truncated.bin", kBlocks);
  FilePager pager(path, kBlocks * kPage, kFramePage, kFrameBudget, 1, GetParam());
  ASSERT_TRUE(pager.use_frames(true));
  std::filesystem::resize_file(path, 4 * kFramePage);
  std::uint32_t frame = 0;
  try {
    pager.pin(pager.base() + 20 * kFramePage, frame);
    ADD_FAILURE() << "a read past the file's new end succeeded";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path + ": reading page 20"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("the file ends early"), std::string::npos) << error.what();
  }
  for (std::size_t page = 0; page < 3; ++page) {  // every frame but the failed read's is still free
    const std::byte* shown = pager.pin(pager.base() + page * kFramePage, frame);
    ASSERT_NE(shown, nullptr);
    EXPECT_EQ(reinterpret_cast<const std::uint32_t*>(shown)[5], page * kBlocksPerFramePage * 1000 + 5);
    pager.unpin(frame);
  }
  std::filesystem::remove(path);
}

TEST_P(FilePagerDeathTest, AFileCutShortWhilePagedIsAClearErrorNamingIt) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string path = numbered_file("pager_truncated.bin");
  FilePager pager(path, kPages * kPage, kPage, 4 * kPage, 1, GetParam());
  EXPECT_EQ(word(pager, 2, 3), 2003u);
  std::filesystem::resize_file(path, 4 * kPage);
  // A probe's announced read: an exception naming the file.
  try {
    pager.touch(pager.base() + 10 * kPage);
    ADD_FAILURE() << "a read past the file's new end succeeded";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path + ": reading page 10"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("the file ends early"), std::string::npos) << error.what();
  }
  // A read no probe announced faults inside a signal handler: the message, then exit 1.
  EXPECT_EXIT((void)word(pager, 12, 0), ::testing::ExitedWithCode(1), "reading page 12 .* the file ends early");
  EXPECT_EQ(word(pager, 3, 5), 3005u);  // the pages still in the file read as before
}

}  // namespace
}  // namespace wavetrace
