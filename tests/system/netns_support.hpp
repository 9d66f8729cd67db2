// Network namespaces for system tests that need more than one host (test_netns.cpp,
// test_failover_netns.cpp): `ip` bounded by a deadline, an RAII owner of the namespaces a test
// creates (deleting a namespace deletes its veth ends and bridge), and the bbw profiles with a
// participant profile `bbw_netns` that uses UDPv4 on one namespace address only, with the other
// namespaces as unicast initial peers. Needs root; callers skip without it.
#pragma once

#include <fcntl.h>
#include <net/if.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <thread>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bbw/runtime/child.hpp"
#include "system_test_support.hpp"

namespace bbw::netns_test {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using bbw::runtime::Child;
using bbw::runtime::Clock;

// Namespaces of these tests are named <prefix><pid>_<role>; a killed run's are removed by the next.
inline constexpr const char* kNsPrefix = "bbwnt";

inline std::string ip_binary() {
  for (const char* p : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"}) {
    if (::access(p, X_OK) == 0) return p;
  }
  return {};
}

struct CmdResult {
  bool ok = false;
  std::string what;  // the command, its exit and stderr when it failed
};

// Runs `ip ARGS...` bounded by 5 s; output in `dir`.
inline CmdResult ip(const std::string& dir, const std::vector<std::string>& args) {
  std::vector<std::string> argv{ip_binary()};
  argv.insert(argv.end(), args.begin(), args.end());
  std::string cmd;
  for (const auto& a : argv) cmd += (cmd.empty() ? "" : " ") + a;
  Child c("ip", argv, dir + "/ip.out", dir + "/ip.err");
  auto st = c.wait_until(Clock::now() + 5s);
  if (!st) st = c.stop(500ms);
  if (st->ok()) return {true, cmd};
  return {false, cmd + ": " + st->describe() + ": " + bbw::system_test::slurp(dir + "/ip.err")};
}

// Owns the namespaces; deleting a namespace deletes the veth ends and the bridge inside it, and
// a veth pair goes with either end.
class Namespaces {
 public:
  explicit Namespaces(std::string dir) : dir_(std::move(dir)) {}
  ~Namespaces() {
    for (auto it = names_.rbegin(); it != names_.rend(); ++it) ip(dir_, {"netns", "del", *it});
  }
  Namespaces(const Namespaces&) = delete;
  Namespaces& operator=(const Namespaces&) = delete;

  CmdResult add(const std::string& name) {
    CmdResult r = ip(dir_, {"netns", "add", name});
    if (r.ok) names_.push_back(name);
    return r;
  }

  // Namespaces of an earlier run of this test that was killed before its guard ran.
  static void remove_orphans(const std::string& dir) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator("/run/netns", fs::directory_options::skip_permission_denied, ec)) {
      const std::string n = e.path().filename().string();
      if (n.rfind(kNsPrefix, 0) != 0) continue;
      const std::string pid = n.substr(std::string(kNsPrefix).size(), n.find('_') - std::string(kNsPrefix).size());
      if (pid.empty() || fs::exists("/proc/" + pid)) continue;
      ip(dir, {"netns", "del", n});
    }
  }

 private:
  std::string dir_;
  std::vector<std::string> names_;
};

// bbw_profiles.xml plus a UDPv4 transport allowed on `address` only and a participant profile
// `bbw_netns` that uses it, with the other namespaces' addresses as unicast initial peers.
inline std::string netns_profiles(const std::string& address, const std::vector<std::string>& peers) {
  std::string xml = bbw::system_test::slurp(bbw::system_test::src("config/dds/bbw_profiles.xml"));
  const std::string transport =
      "      <transport_descriptor>\n"
      "        <transport_id>bbw_udp_netns</transport_id>\n"
      "        <type>UDPv4</type>\n"
      "        <interfaceWhiteList><address>" + address + "</address></interfaceWhiteList>\n"
      "        <maxInitialPeersRange>4</maxInitialPeersRange>\n"
      "      </transport_descriptor>\n";
  std::string locators;
  for (const auto& p : peers) locators += "            <locator><udpv4><address>" + p + "</address></udpv4></locator>\n";
  const std::string participant =
      "    <participant profile_name=\"bbw_netns\">\n"
      "      <rtps>\n"
      "        <builtin>\n"
      "          <discovery_config>\n"
      "            <leaseDuration><sec>2</sec></leaseDuration>\n"
      "            <leaseAnnouncement><sec>0</sec><nanosec>200000000</nanosec></leaseAnnouncement>\n"
      "            <initialAnnouncements><count>5</count><period><sec>0</sec><nanosec>30000000</nanosec></period>"
      "</initialAnnouncements>\n"
      "          </discovery_config>\n"
      "          <initialPeersList>\n" + locators +
      "          </initialPeersList>\n"
      "        </builtin>\n"
      "        <useBuiltinTransports>false</useBuiltinTransports>\n"
      "        <userTransports><transport_id>bbw_udp_netns</transport_id></userTransports>\n"
      "      </rtps>\n"
      "    </participant>\n";
  const auto td = xml.find("</transport_descriptors>");
  if (td == std::string::npos) return {};
  xml.insert(td, transport);
  const auto pe = xml.find("</profiles>");
  if (pe == std::string::npos) return {};
  xml.insert(pe, participant);
  return xml;
}

// Sets `dev` in namespace `ns` up or down from this process, in a thread that enters the
// namespace (setns affects the calling thread only): no fork and exec, so the instant of the
// change is known to microseconds. `before_s`/`after_s`: CLOCK_MONOTONIC seconds around the
// ioctl. Returns "" or what failed.
inline std::string set_link(const std::string& ns, const std::string& dev, bool up, double& before_s, double& after_s) {
  std::string error;
  std::thread t([&] {
    const int nsfd = ::open(("/run/netns/" + ns).c_str(), O_RDONLY | O_CLOEXEC);
    if (nsfd < 0 || ::setns(nsfd, CLONE_NEWNET) != 0) {
      error = "cannot enter /run/netns/" + ns + ": " + std::strerror(errno);
      if (nsfd >= 0) ::close(nsfd);
      return;
    }
    ::close(nsfd);
    const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, dev.c_str(), IFNAMSIZ - 1);
    if (s < 0 || ::ioctl(s, SIOCGIFFLAGS, &ifr) != 0) {
      error = "cannot read the flags of " + dev + " in " + ns + ": " + std::strerror(errno);
    } else {
      if (up) ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP);
      else ifr.ifr_flags = static_cast<short>(ifr.ifr_flags & ~IFF_UP);
      auto now = [] { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); };
      before_s = now();
      const int rc = ::ioctl(s, SIOCSIFFLAGS, &ifr);
      after_s = now();
      if (rc != 0) error = "cannot set " + dev + (up ? " up" : " down") + " in " + ns + ": " + std::strerror(errno);
    }
    if (s >= 0) ::close(s);
  });
  t.join();
  return error;
}

}  // namespace bbw::netns_test
