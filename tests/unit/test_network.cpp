// The network front end (designs and ENI files), and the bus tables the
// generator embeds from a catalogue and a network (golden files in
// tests/golden/bus_*.golden; regenerate with UPDATE_GOLDEN=1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "ethercat/emit_catalogue.h"
#include "ethercat/esi_reader.h"
#include "ethercat/network_reader.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

namespace fs = std::filesystem;

Catalogue small_catalogue() {
    Catalogue cat;
    std::ostringstream err;
    EXPECT_TRUE(load_catalogue({source_path("tests/esi_ok/small_io.xml")}, cat, err)) << err.str();
    return cat;
}

struct NetRead {
    Network net;
    Diagnostics diags;
    bool ok = false;
};

NetRead read_net(const std::string& text, const Catalogue& cat) {
    NetRead r;
    r.ok = read_network(text, "net.xml", cat, r.net, r.diags);
    return r;
}

// The catalogue of corpus ESI files; false when the corpus is absent.
bool corpus_catalogue(const std::vector<std::string>& names, Catalogue& cat) {
    std::vector<std::string> paths;
    for (const std::string& n : names) {
        paths.push_back(source_path("../shared/corpus/esi/" + n));
        if (!fs::exists(paths.back())) return false;
    }
    std::ostringstream err;
    EXPECT_TRUE(load_catalogue(paths, cat, err)) << err.str();
    return true;
}

TEST(Design, ResolvesTypesIdentitiesAndRevisions) {
    Catalogue cat = small_catalogue();
    NetRead r = read_net(read_file(source_path("tests/network/small_design.xml")), cat);
    ASSERT_TRUE(r.ok) << r.diags.format("net.xml");
    ASSERT_EQ(r.net.slaves.size(), 4u);
    const auto& s = r.net.slaves;
    EXPECT_FALSE(r.net.from_eni);
    // EK1100: the only revision in small_io.xml.
    EXPECT_EQ(s[0].position, 0);
    EXPECT_EQ(s[0].type, "EK1100");
    EXPECT_EQ(s[0].vendor, 2u);
    EXPECT_EQ(s[0].product, 0x044c2c52u);
    EXPECT_EQ(s[0].revision, 0x00120000u);
    EXPECT_FALSE(s[0].revision_given);
    EXPECT_EQ(s[0].name, "EtherCAT Coupler");
    EXPECT_TRUE(s[0].entries.empty());
    // EL1004 with an instance name; default process data: the three PDOs with Sm, not the one without.
    EXPECT_EQ(s[1].name, "Inputs left");
    EXPECT_EQ(s[1].product, 0x03ec3052u);
    ASSERT_EQ(s[1].entries.size(), 4u);  // three inputs and a padding bit
    EXPECT_EQ(s[1].input_bits, 4u);
    EXPECT_EQ(s[1].output_bits, 0u);
    EXPECT_EQ(s[1].entries[2].entry.index, 0x6020);
    EXPECT_EQ(s[1].entries[2].bit_offset, 2u);
    EXPECT_TRUE(s[1].entries[3].entry.is_padding());
    // "el2004" (other case) with the older of two revisions, and a station address.
    EXPECT_EQ(s[2].type, "EL2004");
    EXPECT_EQ(s[2].revision, 0x00100000u);
    EXPECT_TRUE(s[2].revision_given);
    EXPECT_EQ(s[2].station, 0x1003);
    EXPECT_EQ(s[2].output_bits, 24u);
    EXPECT_EQ(s[2].entries[2].bit_offset, 8u);  // after a BOOL and a BIT7
    EXPECT_TRUE(s[2].entries[2].output);
    EXPECT_EQ(s[2].entries[0].logical_bit, -1);  // the master maps it at run time
    ASSERT_EQ(s[2].sms.size(), 1u);  // the model's <Sm>
    EXPECT_EQ(s[2].sms[0].start, 0x0f00);
    EXPECT_EQ(s[2].sms[0].control, 0x44);
    // A model without an ESI file: numbers only.
    EXPECT_EQ(s[3].vendor, 0x6au);
    EXPECT_EQ(s[3].product, 0x00414b44u);
    EXPECT_EQ(s[3].device, -1);
    EXPECT_TRUE(s[3].type.empty());
}

TEST(Design, NewestRevisionWhenNoneIsGiven) {
    NetRead r = read_net("<network><slave type=\"EL2004\"/></network>", small_catalogue());
    ASSERT_TRUE(r.ok) << r.diags.format("net.xml");
    EXPECT_EQ(r.net.slaves[0].revision, 0x00110000u);
}

TEST(Design, IdentityFoundInTheCatalogueGetsItsModel) {
    NetRead r = read_net("<network>\n<slave vendor=\"2\" product=\"#x03ec3052\"/>\n</network>", small_catalogue());
    ASSERT_TRUE(r.ok) << r.diags.format("net.xml");
    EXPECT_EQ(r.net.slaves[0].type, "EL1004");
    EXPECT_EQ(r.net.slaves[0].line, 2);
    EXPECT_EQ(r.net.slaves[0].entries.size(), 4u);
}

TEST(Design, TypeWithoutAnyEsiFile) {
    NetRead r = read_net("<network>\n<slave type=\"EK1100\"/>\n</network>", Catalogue{});
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(contains(r.diags.format("net.xml"),
                         "net.xml:2: error: slave type 'EK1100' needs the ESI file that describes it (--esi)"))
        << r.diags.format("net.xml");
}

TEST(Design, TypeNamingTwoProducts) {
    Catalogue cat;
    if (!corpus_catalogue({"Elmo_ECAT_00010420_V11.xml"}, cat)) GTEST_SKIP() << "corpus absent";
    NetRead r = read_net("<network>\n<slave type=\"Elmo Drive\"/>\n</network>", cat);
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(contains(r.diags.format("net.xml"), "net.xml:2: error: slave type 'Elmo Drive' names more than one "
                                                    "product (0x00030924, 0x00030925)"))
        << r.diags.format("net.xml");
}

TEST(Eni, TwinCatFiveSlaves) {
    const std::string path = source_path("../shared/corpus/eni/twincat_5_slaves_eni.xml");
    if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
    NetRead r = read_net(read_file(path), Catalogue{});
    ASSERT_TRUE(r.ok) << r.diags.format("net.xml");
    EXPECT_TRUE(r.net.from_eni);
    // <Info> of each <Slave> (lines 161-167, 786-792, ...), read with grep.
    ASSERT_EQ(r.net.slaves.size(), 5u);
    const char* names[] = {"Imu", "WheelRearLeft", "WheelRearRight", "WheelFrontLeft", "WheelFrontRight"};
    for (int i = 0; i < 5; ++i) {
        const NetSlave& s = r.net.slaves[i];
        EXPECT_EQ(s.position, i);
        EXPECT_EQ(s.name, names[i]);
        EXPECT_EQ(s.station, 1001 + i);
        EXPECT_EQ(s.vendor, i == 0 ? 33u : 154u);
        EXPECT_EQ(s.product, i == 0 ? 1u : 198948u);
        EXPECT_EQ(s.revision, i == 0 ? 65537u : 66592u);
    }
    // Process data: <Recv>/<Send> BitStart, and each entry's bit where <ProcessImage> puts
    // the variable "WheelRearLeft.Inputs.Status word" (BitOffs 872) etc.
    const NetSlave& imu = r.net.slaves[0];
    EXPECT_EQ(imu.input_logical_bit, 568);
    EXPECT_EQ(imu.input_bits, 112u);
    EXPECT_EQ(imu.output_logical_bit, -1);  // no <Send>
    ASSERT_EQ(imu.entries.size(), 7u);
    EXPECT_EQ(imu.entries[0].entry.name, "Acceleration X");
    EXPECT_EQ(imu.entries[0].logical_bit, 568);
    EXPECT_EQ(imu.entries[6].entry.name, "Error code");
    EXPECT_EQ(imu.entries[6].logical_bit, 664);
    // <Sm2> Outputs 4096, ControlByte 100, Enable 0; <Sm3> Inputs, DefaultSize 14, 10240, 32, 1.
    ASSERT_EQ(imu.sms.size(), 2u);
    EXPECT_EQ(imu.sms[0].index, 2);
    EXPECT_EQ(imu.sms[0].type, "Outputs");
    EXPECT_EQ(imu.sms[0].start, 4096);
    EXPECT_EQ(imu.sms[0].control, 100);
    EXPECT_FALSE(imu.sms[0].enable);
    EXPECT_EQ(imu.sms[1].index, 3);
    EXPECT_EQ(imu.sms[1].size, 14);
    EXPECT_EQ(imu.sms[1].start, 10240);
    EXPECT_TRUE(imu.sms[1].enable);
    const NetSlave& wheel = r.net.slaves[1];
    EXPECT_EQ(wheel.output_logical_bit, 776);
    EXPECT_EQ(wheel.output_bits, 48u);
    std::map<std::string, int64_t> bits;
    for (const NetEntry& e : wheel.entries) bits[e.pdo_name + "." + e.entry.name] = e.logical_bit;
    EXPECT_EQ(bits["Inputs.Position actual value"], 776);
    EXPECT_EQ(bits["Inputs.Digital Inputs"], 808);
    EXPECT_EQ(bits["Inputs.Velocity actual value"], 840);
    EXPECT_EQ(bits["Inputs.Status word"], 872);
    EXPECT_EQ(bits["Outputs.Target Velocity"], 776);
    EXPECT_EQ(bits["Outputs.Control word"], 808);
    EXPECT_EQ(bits.size(), 6u);  // only the assigned PDOs (Sm2 <Pdo>5633</Pdo>, Sm3 <Pdo>6659</Pdo>)
    // <Cyclic><Frame>: six commands, <Cnt> on three of them.
    ASSERT_EQ(r.net.cyclic.size(), 6u);
    const NetCommand& lrw = r.net.cyclic[4];
    EXPECT_EQ(lrw.cmd, 12);
    EXPECT_EQ(lrw.logical_address, 16779264u);
    EXPECT_EQ(lrw.length, 56);
    EXPECT_EQ(lrw.expected_wkc, 12);
    EXPECT_EQ(r.net.cyclic[3].expected_wkc, 1);
    EXPECT_EQ(r.net.cyclic[3].cmd, 10);
    EXPECT_EQ(r.net.cyclic[5].cmd, 7);
    EXPECT_EQ(r.net.cyclic[5].ado, 304);
    EXPECT_EQ(r.net.cyclic[5].expected_wkc, 5);
    EXPECT_EQ(r.net.cyclic[0].expected_wkc, -1);
}

TEST(Eni, SlavesOfCatalogueModelsGetTheirType) {
    const std::string eni = source_path("../shared/corpus/eni/twincat_5_slaves_eni.xml");
    Catalogue cat;
    if (!fs::exists(eni) || !corpus_catalogue({"Elmo_ECAT_00010420_V11.xml"}, cat)) GTEST_SKIP() << "corpus absent";
    NetRead r = read_net(read_file(eni), cat);
    ASSERT_TRUE(r.ok) << r.diags.format("net.xml");
    EXPECT_EQ(r.net.slaves[0].device, -1);  // vendor 33: no ESI file
    ASSERT_GE(r.net.slaves[1].device, 0);   // vendor 0x9a, 0x00030924 rev 0x00010420
    EXPECT_EQ(cat.devices[r.net.slaves[1].device].name, "Gold EtherCAT GCON Drive Rev:0x00010420");
    EXPECT_EQ(r.net.slaves[1].name, "WheelRearLeft");  // the instance name stays
}

// --- broken designs and ENI files: tests/network_err ----------------------

std::vector<std::string> err_files() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(source_path("tests/network_err"), ec))
        if (e.path().extension() == ".xml") names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

class NetworkErr : public ::testing::TestWithParam<std::string> {};

TEST_P(NetworkErr, ReportsTheExpectedError) {
    const std::string content = read_file(source_path("tests/network_err/" + GetParam()));
    static const std::regex expect(R"(^<!--\s*expect:\s*(\d+):\s*error:\s*(.*?)\s*-->)");
    std::smatch m;
    const std::string first = content.substr(0, content.find('\n'));
    ASSERT_TRUE(std::regex_search(first, m, expect)) << GetParam() << ": line 1 must be <!-- expect: ... -->";
    NetRead r = read_net(content, small_catalogue());
    EXPECT_FALSE(r.ok);
    const std::string messages = r.diags.format("net.xml");
    const std::string prefix = "net.xml:" + m[1].str() + ": error: ";
    bool found = false;
    std::istringstream lines(messages);
    for (std::string line; std::getline(lines, line);)
        found = found || (line.rfind(prefix, 0) == 0 && contains(line, m[2].str()));
    EXPECT_TRUE(found) << "expected " << prefix << "..." << m[2].str() << "\ngot:\n" << messages;
}

INSTANTIATE_TEST_SUITE_P(Files, NetworkErr, ::testing::ValuesIn(err_files()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                             std::string s = fs::path(info.param).stem().string();
                             for (char& c : s)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return s;
                         });

// --- the embedded tables ----------------------------------------------------

std::string bus_text(const EmbeddedTables& t) {
    std::string out = t.includes + "\n/* declarations */\n" + t.declarations + "\n/* tables */\n" + t.tables +
                      "/* fields */\n";
    for (const std::string& h : t.hf_entries) out += h + "\n";
    return out;
}

void check_bus_golden(const std::string& text, const std::string& name) {
    const std::string path = source_path("tests/golden/" + name);
    if (std::getenv("UPDATE_GOLDEN")) {
        std::ofstream(path, std::ios::binary) << text;
        GTEST_SKIP() << "rewrote " << path;
    }
    const std::string golden = read_file(path);
    ASSERT_FALSE(golden.empty()) << path << " is missing: run with UPDATE_GOLDEN=1";
    EXPECT_EQ(text, golden) << "bus tables differ from " << path << "; if intended, rerun with UPDATE_GOLDEN=1";
}

// small_io.xml and small_design.xml, all devices or the compact catalogue.
void check_small_design(bool compact, const std::string& golden) {
    Catalogue cat = small_catalogue();
    NetRead r = read_net(read_file(source_path("tests/network/small_design.xml")), cat);
    r.net.file = "small_design.xml";
    ASSERT_TRUE(r.ok);
    check_bus_golden(bus_text(emit_bus(cat, {&r.net, compact}, "ecatr")), golden);
}

TEST(BusTables, GoldenSmallDesign) { check_small_design(false, "bus_small_design.golden"); }

TEST(BusTables, GoldenSmallDesignCompact) { check_small_design(true, "bus_small_design_compact.golden"); }

TEST(BusTables, CompactKeepsOnlyTheModelsOfTheNetwork) {
    Catalogue cat = small_catalogue();
    NetRead r = read_net("<network><slave type=\"EL1004\"/><slave type=\"EL1004\"/></network>", cat);
    ASSERT_TRUE(r.ok);
    std::string full = emit_bus(cat, {&r.net, false}, "ecatr").tables;
    std::string compact = emit_bus(cat, {&r.net, true}, "ecatr").tables;
    EXPECT_TRUE(contains(full, "\"EK1100\""));
    EXPECT_FALSE(contains(compact, "\"EK1100\""));
    EXPECT_TRUE(contains(compact, "\"EL1004\""));
    // Two slaves of one model share one field per entry: 3 entries, the padding has none.
    EXPECT_EQ(emit_bus(cat, {&r.net, true}, "ecatr").hf_entries.size(), 3u);
}

// Without a network the run time names the process data of the slaves the
// capture identifies, so every model's default entries get a field; the two
// revisions of the EL2004 share theirs.
TEST(BusTables, CatalogueAloneRegistersAFieldPerModelEntry) {
    Catalogue cat = small_catalogue();
    EmbeddedTables t = emit_bus(cat, {nullptr, false}, "ecatr");
    EXPECT_EQ(t.hf_entries.size(), 6u);
    // 7 default entries and 0x6100:11, which only EL1004's 0x1A10 (not assigned by default) maps;
    // its 5 PDOs and their mappings, 0x1A10 last and not assigned.
    EXPECT_TRUE(contains(t.tables, "ecatr_devices, 4, ecatr_pdo_entries, 8, ecatr_pdos, 5, ecatr_maps, 8,\n"
                                   "    NULL, 0, NULL, 0,\n    NULL, 0"));
    EXPECT_TRUE(contains(t.tables, "    { 0x1a10, 0, 0, 4, 1 },\n"));
    EXPECT_EQ(list_bus_fields(cat, {nullptr, false}, "ecatr"),
              "ecatr.pdo.el1004.channel_1.input\tFT_BOOLEAN\tEL1004 Channel 1.Input\tesi\n"
              "ecatr.pdo.el1004.channel_2.input\tFT_BOOLEAN\tEL1004 Channel 2.Input\tesi\n"
              "ecatr.pdo.el1004.channel_3.input\tFT_BOOLEAN\tEL1004 Channel 3.Input\tesi\n"
              "ecatr.pdo.el2004.channel_1.output\tFT_BOOLEAN\tEL2004 Channel 1.Output\tesi\n"
              "ecatr.pdo.el2004.channel_1.mode\tFT_UINT8\tEL2004 Channel 1.Mode\tesi\n"
              "ecatr.pdo.el2004.channel_1.setpoint\tFT_INT16\tEL2004 Channel 1.Setpoint\tesi\n");
}

// The PDO rows of the embedded tables read back (index, output, assigned by default, mapping as
// "index:subindex/bits" items) must be the catalogue's PDOs: an RxPdo is an output, a TxPdo an input.
using PdoRow = std::tuple<unsigned, bool, bool, std::vector<std::string>>;

std::set<PdoRow> pdo_rows(const std::string& tables) {
    const std::regex map_re(R"(\{ 0x([0-9a-f]+), (\d+), (\d+) \})");
    const std::regex pdo_re(R"(\{ 0x([0-9a-f]+), (\d), (\d), (\d+), (\d+) \})");
    auto block = [&](const std::string& name) {
        size_t at = tables.find(name + "[] = {");
        EXPECT_NE(at, std::string::npos) << name;
        return at == std::string::npos ? std::string() : tables.substr(at, tables.find("};", at) - at);
    };
    std::vector<std::string> maps;
    const std::string map_text = block("ecatr_maps");
    for (std::sregex_iterator m(map_text.begin(), map_text.end(), map_re), e; m != e; ++m)
        maps.push_back((*m)[1].str() + ":" + (*m)[3].str() + "/" + (*m)[2].str());
    std::set<PdoRow> rows;
    const std::string pdo_text = block("ecatr_pdos");
    for (std::sregex_iterator m(pdo_text.begin(), pdo_text.end(), pdo_re), e; m != e; ++m) {
        size_t first = std::stoul((*m)[4]), count = std::stoul((*m)[5]);
        EXPECT_LE(first + count, maps.size()) << m->str();
        if (first + count > maps.size()) continue;
        rows.insert({std::stoul((*m)[1], nullptr, 16), (*m)[2] == "1", (*m)[3] == "1",
                     std::vector<std::string>(maps.begin() + first, maps.begin() + first + count)});
    }
    return rows;
}

std::set<PdoRow> catalogue_pdos(const Catalogue& cat) {
    std::set<PdoRow> rows;
    for (const EsiDevice& dev : cat.devices)
        for (const EsiPdo& p : dev.pdos) {
            std::vector<std::string> map;
            for (const EsiEntry& en : p.entries) {
                char item[32];
                std::snprintf(item, sizeof item, "%04x:%u/%u", en.index, en.subindex, en.bit_length);
                map.push_back(item);
            }
            rows.insert({p.index, !p.tx, p.sm >= 0, map});
        }
    return rows;
}

// A catalogue with inputs and outputs, some PDOs not assigned by default, unnamed PDOs and entries.
const char* const kUnnamedEsi = R"(<EtherCATInfo Version="1.6">
  <Vendor><Id>#x00000002</Id><Name>Example</Name></Vendor>
  <Descriptions><Groups><Group><Type>T</Type><Name>T</Name></Group></Groups><Devices>
    <Device Physics="KK">
      <Type ProductCode="#x00001234" RevisionNo="#x00010000">EL9999</Type>
      <Name>Mixed I/O</Name>
      <RxPdo Fixed="1" Sm="2"><Index>#x1600</Index>
        <Entry><Index>#x7000</Index><SubIndex>1</SubIndex><BitLen>1</BitLen><DataType>BOOL</DataType></Entry>
        <Entry><Index>#x7000</Index><SubIndex>2</SubIndex><BitLen>7</BitLen><Name>Mode</Name>
          <DataType>BIT7</DataType></Entry>
      </RxPdo>
      <RxPdo Fixed="1"><Index>#x1601</Index><Name>Spare</Name>
        <Entry><Index>#x7010</Index><SubIndex>1</SubIndex><BitLen>8</BitLen><Name>Value</Name>
          <DataType>USINT</DataType></Entry>
      </RxPdo>
      <TxPdo Fixed="1" Sm="3"><Index>#x1a00</Index><Name>Status</Name>
        <Entry><Index>#x60ab</Index><SubIndex>17</SubIndex><BitLen>16</BitLen><DataType>UINT</DataType></Entry>
      </TxPdo>
    </Device>
  </Devices></Descriptions>
</EtherCATInfo>
)";

Catalogue unnamed_catalogue() {
    Catalogue cat;
    Diagnostics diags;
    EXPECT_TRUE(read_esi(kUnnamedEsi, "unnamed.xml", cat, diags)) << diags.format("unnamed.xml");
    return cat;
}

TEST(BusTables, PdoRowsAreTheCataloguesPdos) {
    for (const Catalogue& cat : {small_catalogue(), unnamed_catalogue()}) {
        std::set<PdoRow> want = catalogue_pdos(cat);
        EXPECT_EQ(pdo_rows(emit_bus(cat, {nullptr, false}, "ecatr").tables), want);
        EXPECT_TRUE(std::any_of(want.begin(), want.end(), [](const PdoRow& r) { return std::get<1>(r); }));
        EXPECT_TRUE(std::any_of(want.begin(), want.end(), [](const PdoRow& r) { return !std::get<1>(r); }));
    }
}

// An entry without a name is named by its object (index in 4 hex digits, subindex), under its
// PDO's name when the PDO has one (the filters, in the order of the default process data); its
// label gives the object as the dissector shows it (subindex in hex), after the PDO's name.
TEST(BusTables, UnnamedEntriesAreNamedByTheirObject) {
    std::istringstream lines(list_bus_fields(unnamed_catalogue(), {nullptr, false}, "ecatr"));
    std::string filters, labels;
    for (std::string line; std::getline(lines, line);) {
        std::vector<std::string> cols;
        for (size_t at = 0, tab; at <= line.size(); at = tab + 1) {
            tab = line.find('\t', at);
            if (tab == std::string::npos) tab = line.size();
            cols.push_back(line.substr(at, tab - at));
        }
        ASSERT_GE(cols.size(), 3u) << line;
        filters += cols[0] + "\n";
        labels += cols[2] + "\n";
    }
    EXPECT_EQ(filters, "ecatr.pdo.el9999.entry_7000_1\necatr.pdo.el9999.mode\necatr.pdo.el9999.status.entry_60ab_17\n");
    EXPECT_EQ(labels, "EL9999 0x7000:01\nEL9999 Mode\nEL9999 Status 0x60ab:11\n");
}

TEST(BusTables, BitNTakesTheSmallestFieldThatHoldsIt) {
    const std::vector<std::pair<unsigned, std::string>> cases = {
        {1, "FT_BOOLEAN"}, {2, "FT_UINT8"},   {7, "FT_UINT8"},   {8, "FT_UINT8"},   {9, "FT_UINT16"},
        {16, "FT_UINT16"}, {17, "FT_UINT32"}, {32, "FT_UINT32"}, {33, "FT_BYTES"},
    };
    for (const auto& [bits, type] : cases)
        EXPECT_EQ(pdo_field_type("BIT" + std::to_string(bits), bits).type, type) << "BIT" << bits;
}

TEST(BusTables, FieldTypesFollowTheDataType) {
    Catalogue cat = small_catalogue();
    NetRead r = read_net("<network><slave type=\"EL2004\" revision=\"#x00100000\"/></network>", cat);
    ASSERT_TRUE(r.ok);
    std::string fields = list_bus_fields(cat, {&r.net, false}, "ecatr");
    EXPECT_EQ(fields,
              "ecatr.pdo.el2004.channel_1.output\tFT_BOOLEAN\tEL2004 Channel 1.Output\tesi\n"
              "ecatr.pdo.el2004.channel_1.mode\tFT_UINT8\tEL2004 Channel 1.Mode\tesi\n"
              "ecatr.pdo.el2004.channel_1.setpoint\tFT_INT16\tEL2004 Channel 1.Setpoint\tesi\n");
}

}  // namespace
}  // namespace dissgen::testing

namespace dissgen::testing {
namespace {

// The block after `marker` up to the closing fence, in docs/manual.md.
std::string manual_block(const std::string& marker) {
    const std::string manual = read_file(source_path("docs/manual.md"));
    size_t at = manual.find(marker);
    if (at == std::string::npos) return "";
    at += marker.size();
    return manual.substr(at, manual.find("```", at) - at);
}

TEST(ManualBus, DesignExampleIsTheTestedFile) {
    EXPECT_EQ(manual_block("$ cat soem_design.xml\n"), read_file(source_path("tests/network/soem_design.xml")));
}

TEST(ManualBus, WorkedExampleGivesTheFieldsItShows) {
    Catalogue cat;
    if (!corpus_catalogue({"Beckhoff_EK11xx.xml", "Beckhoff_EL1xxx.xml"}, cat)) GTEST_SKIP() << "corpus absent";
    NetRead r = read_net(read_file(source_path("tests/network/soem_design.xml")), cat);
    ASSERT_TRUE(r.ok) << r.diags.format("soem_design.xml");
    EXPECT_EQ(manual_block("--network soem_design.xml | grep pdo.el\n"),
              list_bus_fields(cat, {&r.net, false}, "ecatr"));
    // The listing of `dissgen esi`, filtered as the manual does.
    std::string listing = list_catalogue(cat), shown;
    std::istringstream lines(listing);
    for (std::string line; std::getline(lines, line);)
        if (contains(line, "EK1100 ") || contains(line, "EL1004 ")) shown += line + "\n";
    EXPECT_EQ(manual_block("grep -e 'EK1100 ' -e 'EL1004 '\n"), shown);
}

}  // namespace
}  // namespace dissgen::testing
