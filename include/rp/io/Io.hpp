#pragma once
/// @file
/// Hardware interfacing: I/O boards, hardware servers and device drivers.

#include "rp/io/BarrettHandSerial.hpp"
#include "rp/io/DeviceError.hpp"
#include "rp/io/HwServer.hpp"
#include "rp/io/HwServerIoBoard.hpp"
#include "rp/io/IoBoard.hpp"
#include "rp/io/IoException.hpp"
#include "rp/io/IoStatus.hpp"
#include "rp/io/ModbusIoBoard.hpp"
#include "rp/io/NetFtClient.hpp"
#include "rp/io/SimulatedIoBoard.hpp"
