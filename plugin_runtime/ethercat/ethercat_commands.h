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

inline constexpr command_info commands[] = {
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
inline constexpr unsigned command_count = sizeof commands / sizeof commands[0];
static_assert(command_count == FRMW + 1, "one row per command, in number order");

/* The command's name, or nullptr for a number no command has. */
constexpr const char *command_name_of(unsigned cmd) { return cmd < command_count ? commands[cmd].name : nullptr; }

/* The commands of one class as a set (bit n: command n), worked out from the
 * table when compiling: a class test on every datagram is a shift and a mask. */
template <typename Test>
constexpr uint32_t commands_where(Test test)
{
    uint32_t set = 0;
    for (unsigned c = 0; c < command_count; c++)
        if (test(commands[c])) set |= 1u << c;
    return set;
}
static_assert(command_count <= 32, "a class is a 32-bit set");
constexpr bool in_set(uint32_t set, unsigned cmd) { return cmd < 32 && ((set >> cmd) & 1u); }

inline constexpr uint32_t logical_set = commands_where([](const command_info &i) { return i.addressed_by == ADDRESSING_LOGICAL; });
inline constexpr uint32_t auto_increment_set =
    commands_where([](const command_info &i) { return i.addressed_by == ADDRESSING_AUTO_INCREMENT; });
inline constexpr uint32_t configured_set = commands_where([](const command_info &i) { return i.addressed_by == ADDRESSING_CONFIGURED; });
inline constexpr uint32_t broadcast_set = commands_where([](const command_info &i) { return i.addressed_by == ADDRESSING_BROADCAST; });
inline constexpr uint32_t write_only_set = commands_where([](const command_info &i) { return i.does == ACCESS_WRITE; });
/* Physically addressed (not logical), not ARMW/FRMW: the data is a register's. */
inline constexpr uint32_t register_read_set = commands_where([](const command_info &i) {
    return i.addressed_by != ADDRESSING_LOGICAL && (i.does == ACCESS_READ || i.does == ACCESS_READ_WRITE);
});
inline constexpr uint32_t register_write_set = commands_where([](const command_info &i) {
    return i.addressed_by != ADDRESSING_LOGICAL && (i.does == ACCESS_WRITE || i.does == ACCESS_READ_WRITE);
});

constexpr bool is_logical(unsigned cmd) { return in_set(logical_set, cmd); }
constexpr bool is_auto_increment(unsigned cmd) { return in_set(auto_increment_set, cmd); }
constexpr bool is_configured(unsigned cmd) { return in_set(configured_set, cmd); }
constexpr bool is_broadcast(unsigned cmd) { return in_set(broadcast_set, cmd); }
/* Each slave the datagram passes adds 1 to its slave address (ADP). */
constexpr bool advances_address(unsigned cmd) { return in_set(auto_increment_set | broadcast_set, cmd); }
/* Writes only: its data comes back as the master sent it. */
constexpr bool is_write_only(unsigned cmd) { return in_set(write_only_set, cmd); }
/* Reads (or reads and writes) a slave's registers: the data that comes back is a register's. */
constexpr bool reads_registers(unsigned cmd) { return in_set(register_read_set, cmd); }
/* Writes (or reads and writes) a slave's registers: the data sent is what the registers take. */
constexpr bool writes_registers(unsigned cmd) { return in_set(register_write_set, cmd); }

}  // namespace dg_ecat_commands
