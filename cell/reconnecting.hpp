#pragma once
// A connection to the cell's database that is made again whenever it breaks: a database
// restarted is waited for, not a reason to stop (docs/cell.md, "Faults"). The plan
// workers and the machine hosts hold one each.

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cell/database.hpp"

namespace hybridctl::cell {

class Reconnecting {
 public:
  // `channels` are LISTENed on every connection; `log` hears of losses and returns.
  Reconnecting(std::string uri, std::vector<std::string> channels, std::function<void(const std::string&)> log)
      : uri_(std::move(uri)), channels_(std::move(channels)), log_(std::move(log)) {
    open();
  }
  Database& db() { return *db_; }

  // fn(db), again on a fresh connection while the connection is what failed.
  template <class F>
  auto retrying(F&& fn) {
    for (;;) {
      try {
        return fn(*db_);
      } catch (const DatabaseError& e) {
        if (!e.connection_lost()) throw;
        log_(std::string("database lost (") + e.what() + "); connecting again");
        reopen();
      }
    }
  }

 private:
  void open() {
    db_ = std::make_unique<Database>(uri_);
    for (const std::string& channel : channels_) db_->exec("the " + channel + " channel", "LISTEN " + channel);
  }
  void reopen() {
    for (int attempt = 1;; ++attempt) {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min(2000, 200 * attempt)));
      try {
        open();
        log_("database back");
        return;
      } catch (const DatabaseError& e) {
        if (attempt % 10 == 1) log_(std::string("still no database: ") + e.what());
      }
    }
  }

  std::string uri_;
  std::vector<std::string> channels_;
  std::function<void(const std::string&)> log_;
  std::unique_ptr<Database> db_;
};

}  // namespace hybridctl::cell
