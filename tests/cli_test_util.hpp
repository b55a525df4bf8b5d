#pragma once
// Running the evcorner tool from tests the way a user does: in a scratch folder of its
// own per test, through the shell, both output streams captured.

#include <gtest/gtest.h>
#include <unistd.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_util.hpp"

namespace evcorner::test {

struct CliResult {
    int status;       ///< exit status, -1 when killed
    std::string out;  ///< standard output
    std::string err;  ///< standard error
};

inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

inline std::size_t count_lines(const std::string& s) {
    return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

class CliTest : public ::testing::Test {
protected:
    fs::path dir_;
    fs::path sample_ = bundled_data() / "ecd/shapes_translation/events.txt";

    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               (std::string("evcorner-") + info->test_suite_name() + "-" + info->name() + "-" +
                std::to_string(::getpid()));  // two test runs side by side keep apart
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    /// Runs "evcorner ARGS" from the test's folder, standard input from `stdin_from`.
    CliResult run(const std::string& args, const std::string& stdin_from = "/dev/null") {
        const std::string cmd = "cd '" + dir_.string() + "' && '" EVCORNER_CLI "' " + args + " <" + stdin_from +
                                " >out.stdout 2>out.stderr";
        const int raw = std::system(cmd.c_str());
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir_ / "out.stdout"), slurp(dir_ / "out.stderr")};
    }
    /// Writes a file into the test's folder; returns its path.
    std::string write(const std::string& name, const std::string& content) {
        std::ofstream(dir_ / name, std::ios::binary) << content;
        return (dir_ / name).string();
    }
};

}  // namespace evcorner::test
