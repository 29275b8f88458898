/* EtherCAT's commands (ETG.1000.4, the datagram's first byte): each number,
 * its name as rules/ethercat.xml's Command enum spells it, and the two
 * classes every analysis asks about: how it addresses slaves and what it
 * does to their memory. The one table the analyses (ethercat_analysis.cpp,
 * ethercat_bus.cpp, ethercat_cycles.cpp), the generator's design tables
 * (generator/ethercat/emit_catalogue.cpp) and the report
 * (generator/report/ethercat/timing_model.cpp) read; a unit test keeps it
 * equal to the rule file's enum. Plain C++: no GLib, no Wireshark. */
#pragma once

#include <stdint.h>

namespace dg_ecat_commands {

enum command : uint8_t { NOP, APRD, APWR, APRW, FPRD, FPWR, FPRW, BRD, BWR, BRW, LRD, LWR, LRW, ARMW, FRMW };

/* How a datagram names the slaves it reaches. */
enum addressing : uint8_t {
    ADDRESSING_NONE,           /* NOP: no slave */
    ADDRESSING_AUTO_INCREMENT, /* by position: every slave adds 1 to the address */
    ADDRESSING_CONFIGURED,     /* by configured station address (or alias) */
    ADDRESSING_BROADCAST,      /* every slave (each adds 1 to the address too) */
    ADDRESSING_LOGICAL,        /* a 32-bit logical address, mapped by the slaves' FMMUs */
};

/* What it does to the memory it addresses. */
enum access : uint8_t {
    ACCESS_NONE,                /* NOP */
    ACCESS_READ,                /* the slaves put their data in */
    ACCESS_WRITE,               /* the slaves take the master's data; it comes back as sent */
    ACCESS_READ_WRITE,          /* both, in one pass */
    ACCESS_READ_MULTIPLE_WRITE, /* ARMW/FRMW: one slave reads, the others write what it read */
};

struct command_info {
    const char *name;
    addressing addressed_by;
    access does;
};

constexpr command_info commands[] = {
    {"NOP", ADDRESSING_NONE, ACCESS_NONE},
    {"APRD", ADDRESSING_AUTO_INCREMENT, ACCESS_READ},
    {"APWR", ADDRESSING_AUTO_INCREMENT, ACCESS_WRITE},
    {"APRW", ADDRESSING_AUTO_INCREMENT, ACCESS_READ_WRITE},
    {"FPRD", ADDRESSING_CONFIGURED, ACCESS_READ},
    {"FPWR", ADDRESSING_CONFIGURED, ACCESS_WRITE},
    {"FPRW", ADDRESSING_CONFIGURED, ACCESS_READ_WRITE},
    {"BRD", ADDRESSING_BROADCAST, ACCESS_READ},
    {"BWR", ADDRESSING_BROADCAST, ACCESS_WRITE},
    {"BRW", ADDRESSING_BROADCAST, ACCESS_READ_WRITE},
    {"LRD", ADDRESSING_LOGICAL, ACCESS_READ},
    {"LWR", ADDRESSING_LOGICAL, ACCESS_WRITE},
    {"LRW", ADDRESSING_LOGICAL, ACCESS_READ_WRITE},
    {"ARMW", ADDRESSING_AUTO_INCREMENT, ACCESS_READ_MULTIPLE_WRITE},
    {"FRMW", ADDRESSING_CONFIGURED, ACCESS_READ_MULTIPLE_WRITE},
};
constexpr unsigned command_count = sizeof commands / sizeof commands[0];
static_assert(command_count == FRMW + 1, "one row per command, in number order");

/* The command's name, or nullptr for a number no command has. */
constexpr const char *command_name_of(unsigned cmd) { return cmd < command_count ? commands[cmd].name : nullptr; }

constexpr addressing addressing_of(unsigned cmd) { return cmd < command_count ? commands[cmd].addressed_by : ADDRESSING_NONE; }
constexpr access access_of(unsigned cmd) { return cmd < command_count ? commands[cmd].does : ACCESS_NONE; }

constexpr bool is_logical(unsigned cmd) { return addressing_of(cmd) == ADDRESSING_LOGICAL; }
constexpr bool is_auto_increment(unsigned cmd) { return addressing_of(cmd) == ADDRESSING_AUTO_INCREMENT; }
constexpr bool is_configured(unsigned cmd) { return addressing_of(cmd) == ADDRESSING_CONFIGURED; }
constexpr bool is_broadcast(unsigned cmd) { return addressing_of(cmd) == ADDRESSING_BROADCAST; }
/* Each slave the datagram passes adds 1 to its slave address (ADP). */
constexpr bool advances_address(unsigned cmd) { return is_auto_increment(cmd) || is_broadcast(cmd); }
/* Writes only: its data comes back as the master sent it. */
constexpr bool is_write_only(unsigned cmd) { return access_of(cmd) == ACCESS_WRITE; }
/* Reads (or reads and writes) a slave's registers, addressed physically
 * (not logical, not ARMW/FRMW): the data that comes back is a register's. */
constexpr bool reads_registers(unsigned cmd)
{
    return !is_logical(cmd) && (access_of(cmd) == ACCESS_READ || access_of(cmd) == ACCESS_READ_WRITE);
}
/* Writes (or reads and writes) a slave's registers, addressed physically:
 * the data sent is what the registers take. */
constexpr bool writes_registers(unsigned cmd)
{
    return !is_logical(cmd) && (access_of(cmd) == ACCESS_WRITE || access_of(cmd) == ACCESS_READ_WRITE);
}

}  // namespace dg_ecat_commands
