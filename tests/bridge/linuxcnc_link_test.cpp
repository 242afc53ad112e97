// The bridge's link to its LinuxCNC agent, as a protocol: one JSON line each way per
// request. Here the agent's place is taken by a stand-in that answers its first request
// late (a LinuxCNC that blocks the agent while it shuts down), so that what the link does
// with a reply it stopped waiting for can be seen. The real agent against the real
// LinuxCNC: tests/bridge/linuxcnc_bridge_test.py and bench/soak-bridge.
#include "bridge/linuxcnc_link.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace hybridctl::bridge {
namespace {

namespace fs = std::filesystem;

// A program the link starts as its "python" (it ignores the agent script it is given):
// it answers every status request with LinuxCNC not answering and, as the reason, the
// number of the request it answers; the first answer comes after 1.5 s.
fs::path late_agent() {
  const fs::path path = fs::temp_directory_path() / ("hybridctl-late-agent-" + std::to_string(::getpid()) + ".py");
  std::ofstream(path) << "#!/usr/bin/python3\n"
                         "import json, sys, time\n"
                         "first = True\n"
                         "for line in sys.stdin:\n"
                         "    request = json.loads(line)\n"
                         "    if first:\n"
                         "        time.sleep(1.5)\n"
                         "        first = False\n"
                         "    reply = {'ok': True, 'connected': False, 'why': 'reply to %d' % request.get('id', 0)}\n"
                         "    if 'id' in request:\n"
                         "        reply['id'] = request['id']\n"
                         "    print(json.dumps(reply), flush=True)\n";
  fs::permissions(path, fs::perms::owner_all);
  return path;
}

TEST(LinuxcncLink, AReplyThatComesAfterItsRequestTimedOutIsNotTakenForTheNextOnes) {
  const fs::path agent = late_agent();
  {
    LinuxcncLink::Options options;
    options.python = agent.string();
    options.reply_timeout = std::chrono::milliseconds(500);
    LinuxcncLink link(options);
    EXPECT_THROW(link.status(), LinkError);  // the first request: no answer within 0.5 s
    usleep(1'500'000);                        // its answer arrives meanwhile
    const LinuxcncStatus second = link.status();
    EXPECT_FALSE(second.connected);
    EXPECT_EQ(second.why, "reply to 2") << "the late reply to request 1 was taken for request 2's";
    EXPECT_EQ(link.status().why, "reply to 3");
  }
  fs::remove(agent);
}

}  // namespace
}  // namespace hybridctl::bridge
