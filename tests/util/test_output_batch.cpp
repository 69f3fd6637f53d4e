// Staged outputs: nothing appears before the batch commits, nothing is left when it does
// not, files written on other threads appear at once; output paths checked together.
#include <catch2/catch.hpp>

#include <filesystem>
#include <thread>

#include "test_util.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/output_paths.hpp"

using namespace stipplot;
namespace fs = std::filesystem;

TEST_CASE("a batch's files appear only at its commit", "[util][outputs]") {
  test::TempDir t;
  {
    OutputBatch batch;
    write_file_atomic(t.file("a.txt"), "a");
    write_file_atomic(t.file("b.txt"), "b");
    CHECK(batch.staged() == 2);
    CHECK(!fs::exists(t.file("a.txt")));
    batch.commit();
    CHECK(batch.staged() == 0);
  }
  CHECK(test::read_file(t.file("a.txt")) == "a");
  CHECK(test::read_file(t.file("b.txt")) == "b");
  CHECK(std::distance(fs::directory_iterator(t.path), fs::directory_iterator()) == 2);
}

TEST_CASE("a file written twice in one batch appears once with the newer contents", "[util][outputs]") {
  // A method whose written job came out over its time budget draws again and writes -o
  // once more before the batch commits.
  test::TempDir t;
  {
    OutputBatch batch;
    write_file_atomic(t.file("job.gcode"), "first");
    write_file_atomic(t.file("job.gcode"), "second");
    CHECK(batch.staged() == 1);
    batch.commit();
  }
  CHECK(test::read_file(t.file("job.gcode")) == "second");
  CHECK(std::distance(fs::directory_iterator(t.path), fs::directory_iterator()) == 1);
}

TEST_CASE("a batch dropped uncommitted leaves nothing", "[util][outputs]") {
  test::TempDir t;
  write_file_atomic(t.file("kept.txt"), "old");
  {
    OutputBatch batch;
    write_file_atomic(t.file("kept.txt"), "new");
    write_file_atomic(t.file("c.txt"), "c");
  }  // a failed run: no commit
  CHECK(test::read_file(t.file("kept.txt")) == "old");
  CHECK(std::distance(fs::directory_iterator(t.path), fs::directory_iterator()) == 1);
}

TEST_CASE("files written on another thread than the batch's appear at once", "[util][outputs]") {
  test::TempDir t;
  OutputBatch batch;
  std::thread([&] { write_file_atomic(t.file("w.txt"), "w"); }).join();
  CHECK(test::read_file(t.file("w.txt")) == "w");
  CHECK(batch.staged() == 0);
}

TEST_CASE("outputs are checked against the inputs and each other", "[util][outputs]") {
  test::TempDir t;
  write_file_atomic(t.file("in.png"), "x");
  fs::create_directory(t.file("sub"));
  fs::create_hard_link(t.file("in.png"), t.file("link.png"));
  CHECK_NOTHROW(check_output_paths({{"input", t.file("in.png")}}, {{"-o", t.file("o.svg")}, {"--preview", ""}}));
  CHECK_THROWS_WITH(check_output_paths({{"input", t.file("in.png")}}, {{"--preview", t.file("sub/../in.png")}}),
                    Catch::Contains("would overwrite the input"));
  CHECK_THROWS_WITH(check_output_paths({{"input", t.file("in.png")}}, {{"--preview", t.file("link.png")}}),
                    Catch::Contains("would overwrite the input"));
  CHECK_THROWS_WITH(check_output_paths({}, {{"-o", t.file("a.svg")}, {"--terrain", t.file("./a.svg")}}),
                    Catch::Contains("is also the -o output"));
  CHECK_THROWS_WITH(check_output_paths({}, {{"-o", t.file("sub")}}), Catch::Contains("it is a directory"));
  CHECK_THROWS_WITH(check_output_paths({}, {{"-o", t.file("none/a.svg")}}), Catch::Contains("does not exist"));
}
