#include "pixelgym/trainer/checkpoint_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/trainer/atomic_file.h"
#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using test_folders::entries;
using test_folders::fresh_folder;
using test_folders::mount_tmpfs;
using ::testing::HasSubstr;

// `size` bytes of a pattern that depends on `seed` and on each position.
std::string pattern(std::size_t size, std::uint32_t seed) {
  std::string bytes(size, '\0');
  std::uint32_t state = seed * 2654435761U + 1U;
  for (char& byte : bytes) {
    state = state * 1664525U + 1013904223U;
    byte = static_cast<char>(state >> 24);
  }
  return bytes;
}

CheckpointBlobs sample_blobs() {
  return {{"model", pattern(5000, 1)},
          {"optimizer", pattern(3000, 2)},
          {"rng", std::string("\0\1\2\0", 4)},
          {"normalizer", ""},
          {"meta", R"({"update": 120})"}};
}

std::string read_bytes(const fs::path& path) { return read_whole_file(path, "test"); }

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// What read_checkpoint threw for `path`, or "" when it returned.
std::string read_error(const fs::path& path) {
  try {
    read_checkpoint(path);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

std::uint32_t crc32_of(const std::string& bytes, std::size_t begin, std::size_t end) {
  return static_cast<std::uint32_t>(
      ::crc32_z(0, reinterpret_cast<const Bytef*>(bytes.data() + begin), end - begin));
}

void put_u32(std::string& bytes, std::size_t offset, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<char>((value >> (8 * i)) & 0xFFU);
}

std::uint32_t get_u32(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (int i = 0; i < 4; ++i) {
    value |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[offset + i])) << (8 * i);
  }
  return value;
}

// The offset just past the header CRC (where the blobs start).
std::size_t data_offset(const std::string& bytes) { return 16 + get_u32(bytes, 12) + 4; }

// Rewrites the header CRC so that a deliberate header edit passes the header checksum.
void reseal_header(std::string& bytes) {
  const std::size_t end = 16 + get_u32(bytes, 12);
  put_u32(bytes, end, crc32_of(bytes, 0, end));
}

TEST(CheckpointFileTest, RoundTripsNamedBlobsExactly) {
  const fs::path folder = fresh_folder("ckpt_round_trip");
  const fs::path path = folder / checkpoint_file_name(120);
  const CheckpointBlobs blobs = sample_blobs();
  write_checkpoint(path, blobs);
  EXPECT_EQ(read_checkpoint(path), blobs);
  EXPECT_EQ(entries(folder), std::vector<std::string>{"ckpt-000120.pgck"});
  // Overwriting replaces the whole set.
  const CheckpointBlobs other = {{"model", pattern(10, 9)}};
  write_checkpoint(path, other);
  EXPECT_EQ(read_checkpoint(path), other);
}

TEST(CheckpointFileTest, FileStartsWithMagicAndVersion) {
  const fs::path path = fresh_folder("ckpt_layout") / "c.pgck";
  write_checkpoint(path, sample_blobs());
  const std::string bytes = read_bytes(path);
  EXPECT_EQ(bytes.substr(0, 8), "PGYMCKPT");
  EXPECT_EQ(get_u32(bytes, 8), kCheckpointFormatVersion);
  // The blobs in name order, then the CRC of the blobs.
  std::string data;
  for (const auto& entry : sample_blobs()) data += entry.second;
  EXPECT_EQ(bytes.size(), data_offset(bytes) + data.size() + 4);
  EXPECT_EQ(bytes.substr(data_offset(bytes), data.size()), data);
  EXPECT_EQ(get_u32(bytes, bytes.size() - 4), crc32_of(data, 0, data.size()));
}

TEST(CheckpointFileTest, TruncationAnywhereIsRefusedNamingTheFile) {
  const fs::path folder = fresh_folder("ckpt_truncated");
  const fs::path good = folder / "good.pgck";
  write_checkpoint(good, sample_blobs());
  const std::string bytes = read_bytes(good);
  const std::size_t data = data_offset(bytes);
  // In the magic, the version, the table size, the table, the header CRC, the blobs, the final
  // CRC, and one byte short.
  for (const std::size_t size :
       {std::size_t{0}, std::size_t{5}, std::size_t{10}, std::size_t{14}, std::size_t{20}, data - 2,
        data, data + 1, data + 4000, bytes.size() - 4, bytes.size() - 1}) {
    const fs::path cut = folder / ("cut-" + std::to_string(size) + ".pgck");
    write_bytes(cut, bytes.substr(0, size));
    const std::string error = read_error(cut);
    EXPECT_THAT(error, HasSubstr("read_checkpoint: " + cut.string() + ": truncated: expected "))
        << "cut at " << size;
    EXPECT_THAT(error, HasSubstr("found " + std::to_string(size))) << "cut at " << size;
  }
}

TEST(CheckpointFileTest, TrailingBytesAreRefused) {
  const fs::path path = fresh_folder("ckpt_trailing") / "c.pgck";
  write_checkpoint(path, sample_blobs());
  const std::string bytes = read_bytes(path);
  write_bytes(path, bytes + "x");
  EXPECT_THAT(read_error(path),
              HasSubstr("trailing bytes: expected " + std::to_string(bytes.size()) +
                        " bytes (header and 5 blobs of 8019 bytes in all, then a CRC), found " +
                        std::to_string(bytes.size() + 1)));
}

// Every single-bit flip, anywhere in the file, is refused: none returns data.
TEST(CheckpointFileTest, EveryFlippedBitIsRefused) {
  const fs::path folder = fresh_folder("ckpt_flipped");
  const fs::path path = folder / "c.pgck";
  const CheckpointBlobs small = {{"model", pattern(40, 3)}, {"rng", "abc"}};
  write_checkpoint(path, small);
  const std::string bytes = read_bytes(path);
  const fs::path flipped = folder / "flipped.pgck";
  int refused = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string copy = bytes;
      copy[i] = static_cast<char>(copy[i] ^ (1 << bit));
      write_bytes(flipped, copy);
      const std::string error = read_error(flipped);
      EXPECT_THAT(error, HasSubstr("read_checkpoint: " + flipped.string() + ": "))
          << "byte " << i << " bit " << bit;
      refused += error.empty() ? 0 : 1;
    }
  }
  EXPECT_EQ(refused, static_cast<int>(bytes.size() * 8));
}

TEST(CheckpointFileTest, FlippedBlobByteNamesTheChecksums) {
  const fs::path path = fresh_folder("ckpt_flipped_data") / "c.pgck";
  write_checkpoint(path, sample_blobs());
  std::string bytes = read_bytes(path);
  const std::uint32_t stored = get_u32(bytes, bytes.size() - 4);
  bytes[data_offset(bytes) + 100] = static_cast<char>(bytes[data_offset(bytes) + 100] ^ 0x10);
  write_bytes(path, bytes);
  const std::string error = read_error(path);
  EXPECT_THAT(error, HasSubstr("checksum mismatch: expected CRC-32 0x"));
  EXPECT_THAT(error, HasSubstr("the contents are corrupt; refusing to load it"));
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%08x", stored);
  EXPECT_THAT(error, HasSubstr(hex));
}

TEST(CheckpointFileTest, FlippedTableByteIsAHeaderChecksumMismatch) {
  const fs::path path = fresh_folder("ckpt_flipped_table") / "c.pgck";
  write_checkpoint(path, sample_blobs());
  std::string bytes = read_bytes(path);
  bytes[20] = static_cast<char>(bytes[20] ^ 0x01);
  write_bytes(path, bytes);
  EXPECT_THAT(read_error(path), HasSubstr("header checksum mismatch"));
}

TEST(CheckpointFileTest, WrongMagicIsRefused) {
  const fs::path path = fresh_folder("ckpt_magic") / "c.pgck";
  write_bytes(path, "PK\x03\x04 this is a zip file, not a checkpoint");
  EXPECT_THAT(read_error(path), HasSubstr(": not a pixelgym checkpoint: expected the magic "
                                          "\"PGYMCKPT\" at the start, found \"PK\\x03\\x04 thi\""));
}

TEST(CheckpointFileTest, OtherFormatVersionIsRefused) {
  const fs::path path = fresh_folder("ckpt_version") / "c.pgck";
  write_checkpoint(path, sample_blobs());
  std::string bytes = read_bytes(path);
  put_u32(bytes, 8, 2);
  reseal_header(bytes);
  write_bytes(path, bytes);
  EXPECT_THAT(read_error(path), HasSubstr("expected format version 1, found 2"));
}

// A blob size that disagrees with the file (with a valid header checksum, as a writer bug would
// make it): refused as truncated or trailing, by the size.
TEST(CheckpointFileTest, BlobSizeMismatchIsRefused) {
  const fs::path path = fresh_folder("ckpt_size") / "c.pgck";
  write_checkpoint(path, {{"model", pattern(100, 4)}});
  const std::string bytes = read_bytes(path);
  // Table: count (4), name length (4), "model" (5), size (8) at 16 + 13.
  for (const std::uint32_t size : {101U, 99U}) {
    std::string copy = bytes;
    put_u32(copy, 16 + 13, size);
    reseal_header(copy);
    write_bytes(path, copy);
    EXPECT_THAT(
        read_error(path),
        HasSubstr(size > 100 ? "truncated: expected " + std::to_string(bytes.size() + 1)
                             : "trailing bytes: expected " + std::to_string(bytes.size() - 1)));
  }
}

TEST(CheckpointFileTest, BadBlobSetsAreRejectedBeforeWriting) {
  const fs::path folder = fresh_folder("ckpt_bad_names");
  EXPECT_THROW(write_checkpoint(folder / "a.pgck", {}), std::invalid_argument);
  for (const std::string& name :
       std::vector<std::string>{"", "has space", "a/b", std::string(256, 'x')}) {
    try {
      write_checkpoint(folder / "a.pgck", {{name, "x"}});
      FAIL() << name;
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr("got \"" + name + "\""));
    }
  }
  EXPECT_TRUE(entries(folder).empty());
}

TEST(CheckpointFileTest, FileNamesCarryTheUpdateNumber) {
  EXPECT_EQ(checkpoint_file_name(0), "ckpt-000000.pgck");
  EXPECT_EQ(checkpoint_file_name(120), "ckpt-000120.pgck");
  EXPECT_EQ(checkpoint_file_name(1234567), "ckpt-1234567.pgck");
  EXPECT_THROW(checkpoint_file_name(-1), std::invalid_argument);
  EXPECT_EQ(checkpoint_update("ckpt-000120.pgck"), 120);
  EXPECT_EQ(checkpoint_update("ckpt-1234567.pgck"), 1234567);
  EXPECT_EQ(checkpoint_update(".ckpt-000120.pgck.tmp.77.0"), std::nullopt);
  EXPECT_EQ(checkpoint_update("ckpt-000120.pgck.tmp.77.0"), std::nullopt);
  EXPECT_EQ(checkpoint_update("ckpt-00012a.pgck"), std::nullopt);
  EXPECT_EQ(checkpoint_update("ckpt-120.pgck"), std::nullopt);
  EXPECT_EQ(checkpoint_update("config.json"), std::nullopt);
}

TEST(CheckpointFileTest, LatestSkipsAndReportsInvalidOnesAndIgnoresTemporaries) {
  const fs::path folder = fresh_folder("ckpt_latest");
  for (const int update : {10, 20, 30, 40}) {
    write_checkpoint(folder / checkpoint_file_name(update), {{"meta", std::to_string(update)}});
  }
  // 40 truncated, 30 corrupt; a temporary of 50 left by a kill; other files of a run.
  const std::string forty = read_bytes(folder / checkpoint_file_name(40));
  write_bytes(folder / checkpoint_file_name(40), forty.substr(0, forty.size() / 2));
  std::string thirty = read_bytes(folder / checkpoint_file_name(30));
  thirty[thirty.size() - 6] = static_cast<char>(thirty[thirty.size() - 6] ^ 0x40);
  write_bytes(folder / checkpoint_file_name(30), thirty);
  write_bytes(folder / (temporary_file_prefix(checkpoint_file_name(50)) + "123.0"), "PGYMCK");
  write_bytes(folder / "progress.csv", "steps\n");

  const CheckpointSearch search = find_latest_checkpoint(folder);
  ASSERT_TRUE(search.latest.has_value());
  EXPECT_EQ(search.latest->update, 20);
  EXPECT_EQ(search.latest->path, folder / "ckpt-000020.pgck");
  EXPECT_EQ(search.latest->blobs, (CheckpointBlobs{{"meta", "20"}}));
  ASSERT_EQ(search.skipped.size(), 2U);
  EXPECT_EQ(search.skipped[0].path, folder / "ckpt-000040.pgck");
  EXPECT_THAT(search.skipped[0].reason, HasSubstr("truncated"));
  EXPECT_EQ(search.skipped[1].path, folder / "ckpt-000030.pgck");
  EXPECT_THAT(search.skipped[1].reason, HasSubstr("checksum mismatch"));
  EXPECT_EQ(list_checkpoints(folder).size(), 4U);
}

TEST(CheckpointFileTest, PruningKeepsTheNewestByUpdateNumberAndNothingElseIsTouched) {
  const fs::path folder = fresh_folder("ckpt_prune");
  // Written out of order: the update number decides, not the time of writing.
  for (const int update : {30, 10, 200, 20}) {
    write_checkpoint(folder / checkpoint_file_name(update), {{"meta", std::to_string(update)}});
  }
  write_bytes(folder / (temporary_file_prefix(checkpoint_file_name(300)) + "1.0"), "PGYMCK");
  write_bytes(folder / "progress.csv", "steps\n");

  EXPECT_TRUE(prune_checkpoints(folder, 0).empty());
  EXPECT_EQ(list_checkpoints(folder).size(), 4U);
  EXPECT_TRUE(prune_checkpoints(folder, 4).empty());
  EXPECT_EQ(prune_checkpoints(folder, 2),
            (std::vector<fs::path>{folder / "ckpt-000010.pgck", folder / "ckpt-000020.pgck"}));
  EXPECT_EQ(list_checkpoints(folder),
            (std::vector<fs::path>{folder / "ckpt-000030.pgck", folder / "ckpt-000200.pgck"}));
  EXPECT_TRUE(fs::exists(folder / "progress.csv"));
  EXPECT_TRUE(fs::exists(folder / (temporary_file_prefix(checkpoint_file_name(300)) + "1.0")));
  EXPECT_EQ(read_checkpoint(folder / "ckpt-000200.pgck"), (CheckpointBlobs{{"meta", "200"}}));
  EXPECT_THROW(prune_checkpoints(folder, -1), std::invalid_argument);
}

TEST(CheckpointFileTest, LatestInAFolderWithoutCheckpointsIsNone) {
  const fs::path folder = fresh_folder("ckpt_none");
  write_bytes(folder / (temporary_file_prefix(checkpoint_file_name(1)) + "1.0"), "");
  const CheckpointSearch search = find_latest_checkpoint(folder);
  EXPECT_FALSE(search.latest.has_value());
  EXPECT_TRUE(search.skipped.empty());
  try {
    find_latest_checkpoint(folder / "missing");
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("cannot list " + (folder / "missing").string()));
  }
}

TEST(CheckpointFileTest, ReadOnlyFolderGivesAClearErrorAndLeavesNothing) {
  const fs::path folder = mount_tmpfs("ckpt_read_only", MS_RDONLY, "size=64k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const fs::path path = folder / checkpoint_file_name(1);
  try {
    write_checkpoint(path, sample_blobs());
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("write_checkpoint: cannot write " + path.string() +
                                        ": Read-only file system"));
  }
  EXPECT_TRUE(entries(folder).empty());
}

TEST(CheckpointFileTest, FullDiskKeepsThePreviousCheckpointAndLeavesNoTemporary) {
  const fs::path folder = mount_tmpfs("ckpt_full", 0, "size=64k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const fs::path path = folder / checkpoint_file_name(1);
  write_checkpoint(path, sample_blobs());
  try {
    write_checkpoint(path, {{"model", pattern(200000, 5)}});
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("cannot write " + path.string() + ": No space left on device"));
  }
  EXPECT_EQ(read_checkpoint(path), sample_blobs());
  EXPECT_EQ(entries(folder), std::vector<std::string>{"ckpt-000001.pgck"});
}

// True once a temporary of `name` exists in `folder`: a write of it has started and not finished.
bool temporary_exists(const fs::path& folder, const std::string& name) {
  for (const std::string& entry : entries(folder)) {
    if (entry.rfind(temporary_file_prefix(name), 0) == 0) return true;
  }
  return false;
}

// A child process rewrites one large checkpoint in a loop, alternating two contents, and is
// killed with SIGKILL at a range of points. Under the final name there is always a complete,
// valid checkpoint: the one before the child started, or one the child finished; what a kill
// mid-write leaves is a temporary file, which the latest-checkpoint lookup ignores.
//
// The kills are placed by events, not by a clock (fixed delays after fork() were flaky under
// load: the child might not have started writing yet): the child reports on a pipe as it starts
// each write, the parent waits for the 1st, 2nd or 3rd report and for the temporary of that write
// to appear, then waits 0 to 20 ms more (into the write, its fsync or its rename) and kills.
TEST(CheckpointFileTest, SigkillMidWriteLeavesTheOldOrTheNewCheckpointNeverAPartOne) {
  const fs::path folder = fresh_folder("ckpt_sigkill");
  const fs::path path = folder / checkpoint_file_name(1);
  const std::string name = path.filename().string();
  constexpr std::size_t kSize = 24 << 20;  // 24 MiB: writing and syncing it takes a while
  const std::vector<CheckpointBlobs> contents = {
      {{"model", pattern(kSize, 10)}, {"meta", "first"}},
      {{"model", pattern(kSize, 11)}, {"meta", "second"}},
      {{"model", pattern(kSize, 12)}, {"meta", "third"}}};
  write_checkpoint(path, contents[0]);

  int killed_mid_write = 0;
  std::vector<int> seen(contents.size(), 0);
  const std::vector<int> extra_delays_ms = {0, 1, 5, 20};
  for (int round = 0; round < 12; ++round) {
    const int writes_started = 1 + round % 3;
    const int extra_delay_ms = extra_delays_ms[static_cast<std::size_t>(round / 3)];
    int report[2];
    ASSERT_EQ(::pipe(report), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(report[0]);
      try {
        for (std::size_t i = 1;; i = 3 - i) {
          const char started = 's';
          if (::write(report[1], &started, 1) != 1) ::_exit(4);
          write_checkpoint(path, contents[i]);
        }
      } catch (...) {
        ::_exit(3);
      }
    }
    ::close(report[1]);
    for (int started = 0; started < writes_started; ++started) {
      char byte = 0;
      ASSERT_EQ(::read(report[0], &byte, 1), 1) << "the child stopped writing";
    }
    // The write reported last creates its temporary (the child writes forever, so one appears
    // even if that write has already finished under load).
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    bool temporary_seen = false;
    while (!(temporary_seen = temporary_exists(folder, name)) &&
           std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (temporary_seen) std::this_thread::sleep_for(std::chrono::milliseconds(extra_delay_ms));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ::close(report[0]);  // only now: the child must not die of SIGPIPE before the kill
    ASSERT_TRUE(temporary_seen) << "round " << round
                                << ": no temporary file in 10 s; the checkpoint is not written "
                                   "under a temporary name";
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the child exited itself";

    const CheckpointBlobs read = read_checkpoint(path);  // throws on a partial file
    bool known = false;
    for (std::size_t i = 0; i < contents.size(); ++i) {
      if (read == contents[i]) {
        known = true;
        ++seen[i];
      }
    }
    EXPECT_TRUE(known) << "round " << round << ": a checkpoint no one wrote";
    if (writes_started >= 2) {
      EXPECT_NE(read, contents[0]) << "round " << round << ": a finished write is not in place";
    }
    const CheckpointSearch search = find_latest_checkpoint(folder);
    ASSERT_TRUE(search.latest.has_value());
    EXPECT_EQ(search.latest->blobs, read);
    EXPECT_TRUE(search.skipped.empty());
    // Leftover temporaries: the kill landed mid-write. Remove them for the next round.
    bool temporary_left = false;
    for (const std::string& entry : entries(folder)) {
      if (entry != name) {
        EXPECT_EQ(entry.rfind(temporary_file_prefix(name), 0), 0U) << entry;
        fs::remove(folder / entry);
        temporary_left = true;
      }
    }
    killed_mid_write += temporary_left ? 1 : 0;
  }
  // The test tests something: kills landed mid-write (the rounds without extra delay kill with a
  // temporary present, unless the write finished in the microseconds between the look and the
  // kill), and the child finished writes.
  EXPECT_GE(killed_mid_write, 3);
  EXPECT_GE(seen[1] + seen[2], 8);
}

}  // namespace
}  // namespace pixelgym::trainer
