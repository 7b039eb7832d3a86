#pragma once
/// @file
/// Client of the ATI Net F/T Raw Data Transfer (RDT) protocol over UDP.

#include <array>
#include <cstdint>
#include <string>

#include "rp/io/DeviceError.hpp"
#include "rp/io/IoStatus.hpp"
#include "rp/math/Matrix.hpp"

namespace rp {

/// One force/torque record of the RDT stream, decoded and scaled.
struct NetFtRecord {
  std::uint32_t rdtSequence = 0;  ///< position in this output stream (first record = 1)
  std::uint32_t ftSequence = 0;   ///< the sensor's internal sample number since power-up
  std::uint32_t status = 0;       ///< the sensor's status word (0 = OK)
  std::array<std::int32_t, 6> counts{};  ///< raw Fx, Fy, Fz, Tx, Ty, Tz [counts]
  Vector<3> force = Vector<3>::Zero();   ///< force in the sensor frame [N]
  Vector<3> torque = Vector<3>::Zero();  ///< torque in the sensor frame [N m]
};

/// Talks to an ATI Net F/T (or Ethernet Axia) over its RDT UDP interface
/// (reference: `refdata/08_ati_netft_rdt_protocol.txt`): 8-byte big-endian requests
/// (header 0x1234, command, sample count) to UDP port 49152, 36-byte big-endian records back
/// (RDT sequence, F/T sequence, status, six 32-bit counts). Forces are counts / countsPerForce,
/// torques counts / countsPerTorque.
///
/// The RDT sequence number detects lost and reordered datagrams: a gap adds to `lostRecords()`,
/// a record older than the newest one is counted in `outOfOrderRecords()` and discarded. A record
/// that arrives late fills its gap: it is counted as out of order, not as lost as well (for the 64
/// sequence numbers below the newest; an older straggler stays counted as lost too).
/// Datagrams that are not a whole number of 36-byte records are counted in `malformedPackets()`.
///
/// `receive()` with a zero timeout never blocks and does not allocate, so a servo loop may call
/// it every cycle to fetch the newest record.
class NetFtClient {
 public:
  /// Address and scaling.
  struct Config {
    std::string address = "127.0.0.1";  ///< IPv4 address of the sensor
    int port = 49152;                   ///< RDT UDP port (49152 on every Net F/T)
    double countsPerForce = 1000000.0;  ///< counts per newton (the sensor's cfgcpf)
    double countsPerTorque = 1000000.0; ///< counts per newton metre (the sensor's cfgcpt)
  };

  /// RDT command codes (Net F/T manual, table 10.1).
  enum class Command : std::uint16_t {
    kStop = 0x0000,            ///< stop streaming
    kStartRealtime = 0x0002,   ///< start high-speed real-time streaming
    kStartBuffered = 0x0003,   ///< start high-speed buffered streaming
    kResetLatch = 0x0041,      ///< reset the threshold latch
    kSetBias = 0x0042          ///< set the software bias (tare) to the current load
  };

  /// Creates the client (the socket is opened by `open()`).
  /// @param[in] config  address and scale factors
  /// @throws IoException if the address is not an IPv4 address, the port is out of range or a scale is not positive
  /// Real-time safe: no.
  explicit NetFtClient(const Config& config);
  ~NetFtClient();
  NetFtClient(const NetFtClient&) = delete;             ///< not copyable
  NetFtClient& operator=(const NetFtClient&) = delete;  ///< not copyable

  /// Opens a UDP socket connected to the sensor.
  /// @return `kOk` or `kNotConnected`
  /// Real-time safe: no.
  IoStatus open() noexcept;
  /// Closes the socket (does not send a stop request).
  /// Real-time safe: no.
  void close() noexcept;
  /// True while the socket is open.
  /// Real-time safe: yes.
  bool isOpen() const noexcept { return fd_ >= 0; }

  /// Sends one 8-byte RDT request.
  /// @param[in] command  the command code
  /// @param[in] sampleCount  number of records to stream (0 = until stopped), written as a 32-bit big-endian value
  /// @return `kOk`, or `kNotConnected` (socket not open; the sensor refused: ICMP port unreachable)
  /// Real-time safe: yes (one sendto).
  IoStatus sendRequest(Command command, std::uint32_t sampleCount = 0) noexcept;
  /// Starts high-speed real-time streaming and resets the sequence tracking.
  /// @param[in] sampleCount  number of records (0 = until stopStreaming())
  /// @return as sendRequest()
  /// Real-time safe: yes.
  IoStatus startStreaming(std::uint32_t sampleCount = 0) noexcept;
  /// Stops streaming.
  /// @return as sendRequest()
  /// Real-time safe: yes.
  IoStatus stopStreaming() noexcept { return sendRequest(Command::kStop); }
  /// Asks the sensor to take its current load as zero (software bias).
  /// @return as sendRequest()
  /// Real-time safe: yes.
  IoStatus bias() noexcept { return sendRequest(Command::kSetBias); }

  /// Fetches the newest record, draining every datagram that has arrived.
  /// @param[out] record  the newest in-order record (unchanged unless the result is `kOk` or `kDataLoss`)
  /// @param[in] timeoutMs  how long to wait if nothing has arrived [ms]; 0 = do not wait
  /// @return `kOk`; `kDataLoss` (a newer record was delivered but records were lost or reordered
  ///         since the last call); `kTimeout` (nothing arrived); `kProtocolError` (only malformed
  ///         datagrams arrived); `kDeviceError` (the record's status word is not 0); `kNotConnected`
  ///         (socket closed, or the sensor's port is unreachable)
  /// Real-time safe: yes with timeoutMs = 0 (non-blocking recv into a fixed buffer).
  IoStatus receive(NetFtRecord& record, int timeoutMs = 0) noexcept;

  /// Decodes one 36-byte big-endian RDT record and scales it.
  /// @param[in] bytes  the 36 bytes of the record
  /// @param[in] countsPerForce  counts per newton
  /// @param[in] countsPerTorque  counts per newton metre
  /// @return the decoded record
  /// Real-time safe: yes.
  static NetFtRecord decode(const std::uint8_t* bytes, double countsPerForce, double countsPerTorque) noexcept;
  /// Encodes an 8-byte RDT request (header 0x1234, command, count, all big-endian).
  /// @param[in] command  command code
  /// @param[in] sampleCount  sample count
  /// @param[out] bytes  the 8 request bytes
  /// Real-time safe: yes.
  static void encodeRequest(Command command, std::uint32_t sampleCount, std::uint8_t* bytes) noexcept;

  /// Records received and accepted in order since startStreaming().
  /// Real-time safe: yes.
  std::uint64_t receivedRecords() const noexcept { return received_; }
  /// Records missing from the sequence (gaps not filled by a late record) since startStreaming().
  /// Real-time safe: yes.
  std::uint64_t lostRecords() const noexcept { return lost_; }
  /// Records that arrived after a newer one since startStreaming() (discarded).
  /// Real-time safe: yes.
  std::uint64_t outOfOrderRecords() const noexcept { return outOfOrder_; }
  /// Datagrams whose size is not a multiple of 36 bytes since startStreaming() (discarded).
  /// Real-time safe: yes.
  std::uint64_t malformedPackets() const noexcept { return malformed_; }

  /// Status of the last failed call (`kOk` if none).
  /// Real-time safe: yes.
  IoStatus lastStatus() const noexcept { return error_.status(); }
  /// Message of the last failed call, e.g. `"NetFt 127.0.0.1:49152: no record within 100 ms"`.
  /// Real-time safe: yes.
  const char* lastError() const noexcept { return error_.message(); }

 private:
  Config config_;
  int fd_ = -1;
  bool haveSequence_ = false;
  std::uint32_t lastSequence_ = 0;
  std::uint64_t missing_ = 0;  // bit i: sequence lastSequence_ - 1 - i was counted lost
  std::uint64_t received_ = 0, lost_ = 0, outOfOrder_ = 0, malformed_ = 0;
  DeviceError error_;
};

}  // namespace rp
