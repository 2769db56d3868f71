// sdpslam: simulate, convert, evaluate and run SLAM on robot logs.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "sdpslam/io/bags.h"
#include "cli_common.h"
#include "sdpslam/core/version.h"

namespace sdpslam::cli {
namespace {
std::vector<CommandInfo>& registry() {
  static std::vector<CommandInfo> commands;
  return commands;
}
}  // namespace

bool register_command(const CommandInfo& info) {
  registry().push_back(info);
  return true;
}

CLI::Validator whole_number(std::uint64_t max) {
  const std::string limit = std::to_string(max);
  return CLI::Validator(
      [max, limit](std::string& text) -> std::string {
        const std::string why = "must be a whole number from 0 to " + limit + ", not '" + text + "'";
        if (text.empty() || text.size() > 20U) return why;
        std::uint64_t value = 0U;
        for (const char c : text) {
          if (c < '0' || c > '9') return why;
          const auto digit = static_cast<std::uint64_t>(c - '0');
          if (value > (max - digit) / 10U) return why;  // value * 10 + digit > max
          value = value * 10U + digit;
        }
        return std::string();
      },
      "0.." + limit);
}

CLI::Validator non_empty() {
  return CLI::Validator([](std::string& text) { return text.empty() ? std::string("must not be empty") : std::string(); },
                        "NONEMPTY");
}

std::uint64_t file_size_kib(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {  // a ROS 2 bag: its files together
    std::uint64_t bytes = 0U;
    for (const auto& e : std::filesystem::directory_iterator(path, ec)) {
      if (e.is_regular_file(ec)) bytes += static_cast<std::uint64_t>(e.file_size(ec));
    }
    return bytes / 1024U;
  }
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<std::uint64_t>(st.st_size) / 1024U : 0U;
}

Progress::Progress(std::string what, std::uint64_t total, bool quiet)
    : what_(std::move(what)), total_(total), terminal_(::isatty(STDERR_FILENO) == 1), quiet_(quiet),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::uint64_t done) {
  if (finished_ || quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  // On a terminal the end (done = total) is drawn at once, but once only.
  const bool end = done >= total_ && drawn_ < total_;
  if (terminal_ && !end && now - last_draw_ < std::chrono::milliseconds(200)) return;
  if (!terminal_ && now - last_draw_ < kPlainInterval) return;
  last_draw_ = now;
  drawn_ = done;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed_s > 0.0 ? static_cast<double>(done) / elapsed_s : 0.0;
  const double pct = total_ > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 0.0;
  const double eta_s = rate > 0.0 && total_ >= done ? static_cast<double>(total_ - done) / rate : 0.0;
  const int eta = static_cast<int>(eta_s + 0.5);
  std::fprintf(stderr, "%s%s %llu/%llu %5.1f%%  %.0f %s/s  ETA %d:%02d%s", terminal_ ? "\r" : "", what_.c_str(),
               static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_), pct, rate,
               what_.c_str(), eta / 60, eta % 60, terminal_ ? "   " : "\n");
  std::fflush(stderr);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (terminal_ && !quiet_) std::fprintf(stderr, "\n");
}

}  // namespace sdpslam::cli

int main(int argc, char** argv) {
  using namespace sdpslam::cli;
  sdpslam::io::enable_bag_formats();  // every command that reads a log reads ROS bags too
  CLI::App app{"sdpslam: Segmented DP-SLAM for wheeled robots (simulate, convert, evaluate, run)"};
  app.set_version_flag("--version", sdpslam::version_string());
  app.require_subcommand(1);

  auto& commands = registry();
  std::sort(commands.begin(), commands.end(),
            [](const CommandInfo& a, const CommandInfo& b) { return a.order < b.order; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (const CommandInfo& c : commands) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    runners.emplace_back(sub, c.setup(*sub));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitUsage;
  }
  try {
    for (auto& [sub, run] : runners) {
      if (sub->parsed()) return run();
    }
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sdpslam: out of memory: the options ask for more memory than this machine gives (lower the "
                         "[map]/[sdp] capacities)\n");
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdpslam: internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitUsage;
}
