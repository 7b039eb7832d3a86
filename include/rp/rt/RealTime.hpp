#pragma once
/// @file
/// Real-time and concurrency: ControlProgram, clocks, logging, Barrier, ReaderWriterLock,
/// Client/Server and TripleBuffer.

#include "rp/rt/Barrier.hpp"
#include "rp/rt/Client.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogRecovery.hpp"
#include "rp/rt/LogWriter.hpp"
#include "rp/rt/ReaderWriterLock.hpp"
#include "rp/rt/Server.hpp"
#include "rp/rt/TripleBuffer.hpp"
