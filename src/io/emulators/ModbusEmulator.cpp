#include "ModbusEmulator.hpp"

#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace rp::emulator {

namespace {
modbus_t* asCtx(void* p) { return static_cast<modbus_t*>(p); }
modbus_mapping_t* asMap(void* p) { return static_cast<modbus_mapping_t*>(p); }
void checkAddress(int address, int count, const char* what) {
  if (address < 0 || address >= count)
    throw std::out_of_range(std::string("ModbusEmulator: ") + what + " " + std::to_string(address) +
                            " out of range (" + std::to_string(count) + ")");
}
}  // namespace

ModbusEmulator::ModbusEmulator() : ModbusEmulator(Config{}) {}

ModbusEmulator::ModbusEmulator(const Config& config)
    : config_(config), switchedOn_(static_cast<std::size_t>(config.coils > 0 ? config.coils : 0), 0) {
  mapping_ = modbus_mapping_new(config.coils, config.discreteInputs, config.holdingRegisters, config.inputRegisters);
  if (mapping_ == nullptr) throw std::runtime_error("ModbusEmulator: cannot allocate the register mapping");
}

ModbusEmulator::~ModbusEmulator() {
  stop();
  modbus_mapping_free(asMap(mapping_));
}

void ModbusEmulator::start() {
  if (running_.load()) return;
  ctx_ = modbus_new_tcp(config_.address.c_str(), config_.port);
  if (ctx_ == nullptr) throw std::runtime_error(std::string("ModbusEmulator: ") + modbus_strerror(errno));
  modbus_set_byte_timeout(asCtx(ctx_), 0, 200000);
  listenFd_ = modbus_tcp_listen(asCtx(ctx_), 16);
  if (listenFd_ < 0) {
    const int err = errno;
    modbus_free(asCtx(ctx_));
    ctx_ = nullptr;
    throw std::runtime_error(std::string("ModbusEmulator: cannot listen on ") + config_.address + ": " +
                             modbus_strerror(err));
  }
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  getsockname(listenFd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  stopRequested_.store(false);
  running_.store(true);
  thread_ = std::thread([this] { serve(); });
}

void ModbusEmulator::stop() {
  if (!running_.load()) return;
  stopRequested_.store(true);
  if (thread_.joinable()) thread_.join();
  ::close(listenFd_);
  listenFd_ = -1;
  modbus_free(asCtx(ctx_));
  ctx_ = nullptr;
  running_.store(false);
}

void ModbusEmulator::serve() {
  std::vector<int> clients;
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  while (!stopRequested_.load()) {
    std::vector<pollfd> fds;
    fds.push_back({listenFd_, POLLIN, 0});
    for (int c : clients) fds.push_back({c, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), 20) <= 0) continue;
    if (fds[0].revents & POLLIN) {
      const int c = ::accept(listenFd_, nullptr, nullptr);
      if (c >= 0) clients.push_back(c);
    }
    for (std::size_t i = 1; i < fds.size(); ++i) {
      const int fd = fds[i].fd;
      if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      modbus_set_socket(asCtx(ctx_), fd);
      const int rc = modbus_receive(asCtx(ctx_), query);
      if (rc < 0) {  // client gone or sent garbage: drop the connection
        ::close(fd);
        std::erase(clients, fd);
        continue;
      }
      if (rc == 0) continue;
      requests_.fetch_add(1);
      switch (fault_.load()) {
        case Fault::kNone: {
          std::lock_guard lock(mutex_);
          auto* map = asMap(mapping_);
          const std::vector<std::uint8_t> before(map->tab_bits, map->tab_bits + config_.coils);
          modbus_reply(asCtx(ctx_), query, rc, map);
          for (int c = 0; c < config_.coils; ++c)
            if (before[static_cast<std::size_t>(c)] == 0 && map->tab_bits[c] != 0) ++switchedOn_[static_cast<std::size_t>(c)];
          break;
        }
        case Fault::kSilent:
          break;
        case Fault::kGarbled: {
          // Same transaction id, a well-formed MBAP header, a function code nobody asked for.
          const std::uint8_t reply[9] = {query[0], query[1], 0, 0, 0, 3, query[6], 0x2B, 0x55};
          [[maybe_unused]] auto n = ::write(fd, reply, sizeof reply);
          break;
        }
        case Fault::kTruncated: {
          const std::uint8_t reply[5] = {query[0], query[1], 0, 0, 0};
          [[maybe_unused]] auto n = ::write(fd, reply, sizeof reply);
          break;
        }
      }
    }
  }
  for (int c : clients) ::close(c);
}

long ModbusEmulator::coilSwitchedOn(int address) const {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.coils, "coil");
  return switchedOn_[static_cast<std::size_t>(address)];
}

bool ModbusEmulator::coil(int address) const {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.coils, "coil");
  return asMap(mapping_)->tab_bits[address] != 0;
}

void ModbusEmulator::setCoil(int address, bool value) {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.coils, "coil");
  asMap(mapping_)->tab_bits[address] = value ? 1 : 0;
}

void ModbusEmulator::setDiscreteInput(int address, bool value) {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.discreteInputs, "discrete input");
  asMap(mapping_)->tab_input_bits[address] = value ? 1 : 0;
}

std::uint16_t ModbusEmulator::holdingRegister(int address) const {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.holdingRegisters, "holding register");
  return asMap(mapping_)->tab_registers[address];
}

void ModbusEmulator::setInputRegister(int address, std::uint16_t value) {
  std::lock_guard lock(mutex_);
  checkAddress(address, config_.inputRegisters, "input register");
  asMap(mapping_)->tab_input_registers[address] = value;
}

}  // namespace rp::emulator
