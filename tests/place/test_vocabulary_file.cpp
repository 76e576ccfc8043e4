#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>

#include "place_test_data.h"
#include "pspslam/core/error.h"
#include "pspslam/place/vocabulary.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string load_error(const fs::path& file) {
  try {
    Vocabulary::load(file);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

class VocabularyFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937_64 rng(21);
    descriptors_ = testing_place::random_descriptors(6000, rng);
    std::vector<cv::Mat> images;
    for (int i = 0; i < 30; ++i) images.push_back(descriptors_.rowRange(i * 200, i * 200 + 200));
    VocabularyParams params;
    params.branching = 5;
    params.levels = 4;
    vocabulary_.emplace(Vocabulary::train(descriptors_, images, params));
    dir_ = testing::make_temp_dir("place");
    file_ = dir_ / "voc.pspvoc";
    vocabulary_->save(file_);
    bytes_ = read_bytes(file_);
  }

  std::string prefix() const { return "vocabulary file '" + file_.string() + "': "; }

  cv::Mat descriptors_;
  std::optional<Vocabulary> vocabulary_;
  fs::path dir_;
  fs::path file_;
  std::string bytes_;
};

TEST_F(VocabularyFile, RoundTripKeepsTreeWeightsAndWords) {
  const Vocabulary& saved = *vocabulary_;
  // 48-byte header + per node 1 + 32 bytes + 4 bytes per word.
  EXPECT_EQ(bytes_.size(), 48 + saved.node_count() * 33 + saved.word_count() * 4);
  const Vocabulary loaded = Vocabulary::load(file_);
  ASSERT_EQ(loaded.branching(), 5);
  ASSERT_EQ(loaded.levels(), 4);
  ASSERT_EQ(loaded.node_count(), saved.node_count());
  ASSERT_EQ(loaded.word_count(), saved.word_count());
  EXPECT_EQ(loaded.training_images(), 30u);
  EXPECT_GT(loaded.word_count(), 400u);
  for (WordId w = 0; w < saved.word_count(); ++w) {
    ASSERT_EQ(loaded.word_weight(w), saved.word_weight(w)) << "word " << w;
    ASSERT_EQ(loaded.word_node(w), saved.word_node(w));
  }
  for (int r = 0; r < descriptors_.rows; ++r) {
    ASSERT_EQ(loaded.word(descriptors_.ptr<std::uint8_t>(r)),
              saved.word(descriptors_.ptr<std::uint8_t>(r)))
        << "row " << r;
  }
  BowVector a;
  BowVector b;
  saved.transform(descriptors_.rowRange(0, 500), a);
  loaded.transform(descriptors_.rowRange(0, 500), b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.entries[i].word, b.entries[i].word);
    EXPECT_EQ(a.entries[i].weight, b.entries[i].weight);
  }
  // Saving the loaded vocabulary gives the same bytes.
  loaded.save(dir_ / "again.pspvoc");
  EXPECT_EQ(read_bytes(dir_ / "again.pspvoc"), bytes_);
}

TEST_F(VocabularyFile, MissingFile) {
  const fs::path missing = dir_ / "nope.pspvoc";
  EXPECT_EQ(load_error(missing),
            "vocabulary file '" + missing.string() + "': cannot open for reading");
}

TEST_F(VocabularyFile, BadMagic) {
  std::string bytes = bytes_;
  bytes[3] = 'X';
  write_bytes(file_, bytes);
  EXPECT_EQ(load_error(file_),
            prefix() + "not a pspslam vocabulary (bad magic, expected \"PSPVOCAB\")");
  write_bytes(file_, "hello world, this is a text file and not a vocabulary at all\n");
  EXPECT_EQ(load_error(file_),
            prefix() + "not a pspslam vocabulary (bad magic, expected \"PSPVOCAB\")");
}

TEST_F(VocabularyFile, WrongVersion) {
  std::string bytes = bytes_;
  const std::uint32_t version = 2;
  std::memcpy(&bytes[8], &version, 4);
  write_bytes(file_, bytes);
  EXPECT_EQ(load_error(file_),
            prefix() + "unsupported format version 2 (this build reads version 1)");
}

TEST_F(VocabularyFile, TruncatedHeaderAndPayload) {
  write_bytes(file_, bytes_.substr(0, 20));
  EXPECT_EQ(load_error(file_), prefix() + "truncated (the header needs 48 bytes, the file has 20)");
  write_bytes(file_, bytes_.substr(0, bytes_.size() - 100));
  EXPECT_EQ(load_error(file_), prefix() + "truncated (expected " + std::to_string(bytes_.size()) +
                                   " bytes, the file has " + std::to_string(bytes_.size() - 100) +
                                   ")");
  write_bytes(file_, bytes_ + "xyz");
  EXPECT_EQ(load_error(file_), prefix() +
                                   "unexpected 3 trailing bytes after the payload "
                                   "(expected " +
                                   std::to_string(bytes_.size()) + " bytes)");
}

TEST_F(VocabularyFile, CorruptPayloadFailsChecksum) {
  std::string bytes = bytes_;
  bytes[48 + vocabulary_->node_count() + 100] ^= 0x10;  // one bit of a centroid
  write_bytes(file_, bytes);
  const std::string message = load_error(file_);
  EXPECT_EQ(message.rfind(prefix() + "checksum mismatch (stored 0x", 0), 0u) << message;
  EXPECT_TRUE(message.ends_with("): the file is corrupt")) << message;
  EXPECT_EQ(message.size(), prefix().size() +
                                std::string("checksum mismatch (stored 0x, "
                                            "computed 0x): the file is corrupt")
                                    .size() +
                                32)
      << message;
}

TEST_F(VocabularyFile, InconsistentHeaderCounts) {
  std::string bytes = bytes_;
  const std::uint32_t nodes = static_cast<std::uint32_t>(vocabulary_->node_count()) + 1;
  std::memcpy(&bytes[20], &nodes, 4);
  write_bytes(file_, bytes);
  const std::string message = load_error(file_);
  EXPECT_EQ(message.rfind(prefix() + "invalid header (payload size ", 0), 0u) << message;
}

}  // namespace
}  // namespace pspslam
