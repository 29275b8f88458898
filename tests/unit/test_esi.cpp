// The ESI front end on the real vendor files of ../shared/corpus/esi (skipped
// when the corpus is not beside the source tree), on hand-made files with the
// quirks real files have (tests/esi_ok), and on broken files (tests/esi_err,
// first line <!-- expect: LINE: error: TEXT -->). Expected identities and
// names were read from the files with grep and by eye, not with this code.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <regex>
#include <sstream>

#include "ethercat/esi_reader.h"
#include "test_support.h"
#include "xml_input.h"

namespace dissgen::testing {
namespace {

namespace fs = std::filesystem;

const std::string kCorpus = "../shared/corpus/esi/";

struct Read {
    Catalogue cat;
    Diagnostics diags;
    bool ok = false;
};

Read read_path(const std::string& path) {
    Read r;
    r.ok = read_esi(read_file(path), path, r.cat, r.diags);
    return r;
}

// Reads a corpus file, or skips the test when the corpus is absent.
#define READ_CORPUS(var, name)                                                              \
    const std::string var##_path = source_path(kCorpus + name);                            \
    if (!fs::exists(var##_path)) GTEST_SKIP() << var##_path << " absent (corpus not here)"; \
    Read var = read_path(var##_path);                                                      \
    ASSERT_TRUE(var.ok) << var.diags.format(name)

const EsiDevice* device(const Catalogue& cat, uint32_t product, uint32_t revision) {
    for (const EsiDevice& d : cat.devices)
        if (d.product == product && d.revision == revision) return &d;
    return nullptr;
}

TEST(EsiCorpus, BeckhoffEL1xxxLatin1Crlf4MB) {
    READ_CORPUS(r, "Beckhoff_EL1xxx.xml");
    EXPECT_EQ(r.cat.devices.size(), 150u);  // grep -c '<Device[ >]'
    for (const EsiDevice& d : r.cat.devices) EXPECT_EQ(d.vendor, 2u);
    const EsiDevice* el1004 = device(r.cat, 0x03ec3052, 0x00130000);  // line 457
    ASSERT_NE(el1004, nullptr);
    EXPECT_EQ(el1004->type, "EL1004");
    EXPECT_EQ(el1004->name, "EL1004 4Ch. Dig. Input 24V, 3ms");  // LcId 1033, not the German 1031
    EXPECT_EQ(el1004->line, 457);
    // <Sm DefaultSize="1" StartAddress="#x1000" ControlByte="0" Enable="1">Inputs</Sm>
    ASSERT_EQ(el1004->sms.size(), 1u);
    EXPECT_EQ(el1004->sms[0].start, 0x1000);
    EXPECT_EQ(el1004->sms[0].size, 1);
    EXPECT_EQ(el1004->sms[0].control, 0);
    EXPECT_TRUE(el1004->sms[0].enable);
    EXPECT_EQ(el1004->sms[0].type, "Inputs");
    ASSERT_EQ(el1004->pdos.size(), 4u);
    for (int i = 0; i < 4; ++i) {
        const EsiPdo& p = el1004->pdos[i];
        EXPECT_TRUE(p.tx);
        EXPECT_EQ(p.index, 0x1a00 + i);
        EXPECT_EQ(p.name, "Channel " + std::to_string(i + 1));
        EXPECT_EQ(p.sm, 0);
        EXPECT_TRUE(p.fixed);
        EXPECT_TRUE(p.mandatory);
        ASSERT_EQ(p.entries.size(), 1u);
        EXPECT_EQ(p.entries[0].index, 0x6000 + 0x10 * i);
        EXPECT_EQ(p.entries[0].subindex, 1);
        EXPECT_EQ(p.entries[0].bit_length, 1);
        EXPECT_EQ(p.entries[0].name, "Input");
        EXPECT_EQ(p.entries[0].data_type, "BOOL");
    }
    // Five revisions of the EL1004 itself (grep 'ProductCode="#x03ec3052"' with type EL1004).
    int revisions = 0;
    for (const EsiDevice& d : r.cat.devices) revisions += d.type == "EL1004";
    EXPECT_EQ(revisions, 5);
    // Upper-case hex digits in the same file: EL1014-0010 is #x03F63052 #x0013000A (line 1947).
    const EsiDevice* el1014 = device(r.cat, 0x03f63052, 0x0013000a);
    ASSERT_NE(el1014, nullptr);
    EXPECT_EQ(el1014->type, "EL1014-0010");
}

TEST(EsiCorpus, BeckhoffEL1xxxReadsFast) {
    const std::string path = source_path(kCorpus + "Beckhoff_EL1xxx.xml");
    if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
    const std::string text = read_file(path);
    auto start = std::chrono::steady_clock::now();
    Catalogue cat;
    Diagnostics diags;
    ASSERT_TRUE(read_esi(text, path, cat, diags));
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // About 0.1 s on the development machine; generous for a loaded CI box.
    EXPECT_LT(seconds, 3.0) << "reading 4 MB of ESI took " << seconds << " s";
}

TEST(EsiCorpus, BeckhoffEK11xx) {
    READ_CORPUS(r, "Beckhoff_EK11xx.xml");
    EXPECT_EQ(r.cat.devices.size(), 24u);
    const EsiDevice* ek = device(r.cat, 0x044c2c52, 0);  // line 30, with HideType lines after <Type>
    ASSERT_NE(ek, nullptr);
    EXPECT_EQ(ek->type, "EK1100");
    EXPECT_EQ(ek->name, "EK1100 EtherCAT Coupler (0.5A E-Bus)");
    EXPECT_NE(device(r.cat, 0x044c2c52, 0x00120000), nullptr);  // the SOEM capture's EK1100
}

TEST(EsiCorpus, BeckhoffCUxxxx) {
    READ_CORPUS(r, "Beckhoff_CUxxxx.xml");
    EXPECT_EQ(r.cat.devices.size(), 20u);
    const EsiDevice* cu = device(r.cat, 0x04635432, 0x00100000);
    ASSERT_NE(cu, nullptr);
    EXPECT_EQ(cu->name, "CU1123 EtherCAT junction (3-ports)");
}

TEST(EsiCorpus, BogusIODecimalRevisionAndChineseName) {
    READ_CORPUS(r, "BogusIO.xml");
    ASSERT_EQ(r.cat.devices.size(), 1u);
    const EsiDevice& d = r.cat.devices[0];
    EXPECT_EQ(d.vendor, 0xB090C0u);
    EXPECT_EQ(d.product, 0xB0901030u);
    EXPECT_EQ(d.revision, 42u);  // RevisionNo="42"
    EXPECT_EQ(d.name, "B090.IO.001 3-ch Digital In/3-ch Digital Out");  // 1033 before 2052
    ASSERT_GE(d.pdos.size(), 2u);
    EXPECT_FALSE(d.pdos[0].tx);  // RxPdo #x1600 Sm="0" (line 34)
    EXPECT_EQ(d.pdos[0].index, 0x1600);
    EXPECT_EQ(d.pdos[0].sm, 0);
    EXPECT_FALSE(d.pdos[0].mandatory);
}

TEST(EsiCorpus, BogusServo) {
    READ_CORPUS(r, "BogusServo.xml");
    ASSERT_EQ(r.cat.devices.size(), 2u);
    EXPECT_EQ(r.cat.devices[0].product, 0xB0905030u);
    EXPECT_EQ(r.cat.devices[0].revision, 13u);
    EXPECT_EQ(r.cat.devices[0].name, "B090.SO.001 Servo Drive");
    EXPECT_EQ(r.cat.devices[1].product, 0xB0905031u);
    EXPECT_EQ(r.cat.devices[1].name, "B090.SO.002 Servo Drive");
}

TEST(EsiCorpus, ElmoRevisionsAndTypeWithTrailingSpace) {
    READ_CORPUS(r, "Elmo_ECAT_00010420_V11.xml");
    ASSERT_EQ(r.cat.devices.size(), 4u);
    for (const EsiDevice& d : r.cat.devices) EXPECT_EQ(d.vendor, 0x9Au);
    const EsiDevice* drive = device(r.cat, 0x00030924, 0x00010420);  // line 1024
    ASSERT_NE(drive, nullptr);
    EXPECT_EQ(drive->type, "Elmo Drive");
    EXPECT_EQ(drive->name, "Gold EtherCAT GCON Drive Rev:0x00010420");
    EXPECT_NE(device(r.cat, 0x00030925, 0x00000001), nullptr);
}

TEST(EsiCorpus, InovanceHexVendorExcludesAndPdosWithoutSm) {
    READ_CORPUS(r, "IS620N_v2.6.7.xml");
    ASSERT_EQ(r.cat.devices.size(), 1u);
    const EsiDevice& d = r.cat.devices[0];
    EXPECT_EQ(d.vendor, 0x00100000u);  // <Id>#x00100000</Id>
    EXPECT_EQ(d.product, 0x000C0108u);  // RevisionNo before ProductCode in <Type>
    EXPECT_EQ(d.revision, 0x00010001u);
    EXPECT_EQ(d.name, "IS620N_ECAT_v2.6.7");
    const EsiPdo* first = nullptr;
    const EsiPdo* assigned = nullptr;
    for (const EsiPdo& p : d.pdos) {
        if (!first && !p.tx && p.index == 0x1600) first = &p;
        if (!assigned && !p.tx && p.sm == 2) assigned = &p;
    }
    ASSERT_NE(first, nullptr);  // line 11140: <RxPdo Fixed="0">, no Sm, five <Exclude>
    EXPECT_EQ(first->sm, -1);
    EXPECT_FALSE(first->fixed);
    EXPECT_EQ(first->excludes, (std::vector<uint16_t>{0x1701, 0x1702, 0x1703, 0x1704, 0x1705}));
    EXPECT_EQ(first->name, "1st receive PDO Mapping");
    ASSERT_NE(assigned, nullptr);  // line 11170: <RxPdo Fixed="1" Sm="2">
    EXPECT_EQ(assigned->line, 11170);
}

TEST(EsiCorpus, IngeniaDecimalIdentityAndGermanOnlyName) {
    READ_CORPUS(r, "eve-xcr-e_esi.xml");
    ASSERT_EQ(r.cat.devices.size(), 1u);
    EXPECT_EQ(r.cat.devices[0].vendor, 0x29cu);
    EXPECT_EQ(r.cat.devices[0].product, 46338049u);  // decimal ProductCode
    EXPECT_EQ(r.cat.devices[0].revision, 327700u);
    EXPECT_EQ(r.cat.devices[0].name, "EVE-XCR-E");  // only LcId 1031: the first name
}

TEST(EsiCorpus, WeidmuellerModularCoupler) {
    READ_CORPUS(r, "Weidmueller_UR20_FBC.xml");
    ASSERT_EQ(r.cat.devices.size(), 2u);
    EXPECT_EQ(r.cat.devices[0].vendor, 0x230u);
    EXPECT_EQ(r.cat.devices[0].product, 0x4F911C30u);
    EXPECT_EQ(r.cat.devices[0].revision, 1u);
    EXPECT_EQ(r.cat.devices[1].revision, 0x00011100u);
    EXPECT_EQ(r.cat.devices[0].name, "UR20-FBC-EC / 1334910000");
    EXPECT_EQ(r.cat.modules.size(), 2u);  // <Modules> after <Devices>
}

TEST(EsiCorpus, WeidmuellerModuleFile) {
    READ_CORPUS(r, "Weidmueller_UR20_IO.xml");
    EXPECT_TRUE(r.cat.devices.empty());
    ASSERT_EQ(r.cat.modules.size(), 82u);
    const EsiModule& m = r.cat.modules[0];
    EXPECT_EQ(m.vendor, 560u);
    EXPECT_EQ(m.ident, 0x00091F84u);
    EXPECT_EQ(m.type, "UR20-4DI-P");
    EXPECT_EQ(m.name, "UR20-4DI-P / 1315170000");
    ASSERT_FALSE(m.pdos.empty());
    EXPECT_EQ(m.pdos[0].index, 0x1A00);
    EXPECT_EQ(m.pdos[0].sm, 3);
    ASSERT_GE(m.pdos[0].entries.size(), 4u);
    EXPECT_EQ(m.pdos[0].entries[3].name, "DI4");
}

TEST(EsiCorpus, WholeFolderListsEveryDeviceSorted) {
    const std::string folder = source_path(kCorpus);
    if (!fs::exists(folder)) GTEST_SKIP() << folder << " absent";
    Catalogue cat;
    std::ostringstream err;
    ASSERT_TRUE(load_catalogue({folder}, cat, err)) << err.str();
    // 20 + 24 + 150 + 1 + 2 + 4 + 1 + 2 + 0 + 1 <Device> elements, no identity twice.
    EXPECT_EQ(cat.devices.size(), 205u);
    std::string listing = list_catalogue(cat);
    EXPECT_TRUE(contains(listing, "0x00000002 0x03ec3052 0x00130000 EL1004 4Ch. Dig. Input 24V, 3ms\n"));
    EXPECT_TRUE(contains(listing, "0x0000029c 0x02c31001 0x00050014 EVE-XCR-E\n"));
    std::istringstream lines(listing);
    std::string line, previous;
    static const std::regex format("0x[0-9a-f]{8} 0x[0-9a-f]{8} 0x[0-9a-f]{8} .+");
    while (std::getline(lines, line)) {
        EXPECT_TRUE(std::regex_match(line, format)) << line;
        EXPECT_LT(previous, line);
        previous = line;
    }
}

// --- hand-made files with the quirks ---------------------------------------

TEST(EsiOk, MixedNumberFormatsFlagsPaddingAndExclude) {
    Read r = read_path(source_path("tests/esi_ok/small_io.xml"));
    ASSERT_TRUE(r.ok) << r.diags.format("small_io.xml");
    ASSERT_EQ(r.cat.devices.size(), 4u);
    const EsiDevice& ek = r.cat.devices[0];
    EXPECT_EQ(ek.name, "EtherCAT Coupler");  // LcId 1033 though 1031 comes first
    const EsiDevice& el = r.cat.devices[1];
    EXPECT_EQ(el.product, 0x03ec3052u);  // 0x hex
    EXPECT_EQ(el.revision, 1245184u);    // decimal
    ASSERT_EQ(el.pdos.size(), 4u);
    EXPECT_TRUE(el.pdos[0].fixed && el.pdos[0].mandatory);  // "true"
    EXPECT_TRUE(el.pdos[1].fixed && el.pdos[1].mandatory);  // "1"
    EXPECT_FALSE(el.pdos[2].mandatory);
    EXPECT_EQ(el.pdos[2].index, 6658);  // decimal index
    ASSERT_EQ(el.pdos[2].entries.size(), 2u);
    EXPECT_TRUE(el.pdos[2].entries[1].is_padding());
    EXPECT_EQ(el.pdos[2].entries[1].bit_length, 1);
    EXPECT_EQ(el.pdos[3].sm, -1);
    EXPECT_EQ(el.pdos[3].excludes, std::vector<uint16_t>{0x1a00});
    EXPECT_EQ(el.pdos[3].entries[0].subindex, 0x11);
}

TEST(EsiOk, Latin1WithCrlf) {
    Read r = read_path(source_path("tests/esi_ok/latin1_crlf.xml"));
    ASSERT_TRUE(r.ok) << r.diags.format("latin1_crlf.xml");
    ASSERT_EQ(r.cat.devices.size(), 1u);
    EXPECT_EQ(r.cat.devices[0].vendor, 0x1Au);
    EXPECT_EQ(r.cat.devices[0].type, "Gr\xc3\xbc\xc3\x9f" "e");  // stored as UTF-8
    EXPECT_EQ(r.cat.devices[0].name, "Eing\xc3\xa4nge");
    EXPECT_EQ(r.cat.devices[0].line, 5);
}

TEST(EsiOk, BomWithoutDeclaration) {
    Read r = read_path(source_path("tests/esi_ok/bom_no_declaration.xml"));
    ASSERT_TRUE(r.ok) << r.diags.format("bom_no_declaration.xml");
    ASSERT_EQ(r.cat.devices.size(), 1u);
    EXPECT_EQ(r.cat.devices[0].revision, 2u);
    EXPECT_EQ(r.cat.devices[0].name, "\xe4\xb8\x9c\xe8\xa5\xbf");  // no 1033: the first name
}

TEST(EsiOk, ModuleFileWithBomAndDeclaration) {
    Read r = read_path(source_path("tests/esi_ok/module_file_bom.xml"));
    ASSERT_TRUE(r.ok) << r.diags.format("module_file_bom.xml");
    ASSERT_EQ(r.cat.modules.size(), 1u);
    EXPECT_EQ(r.cat.modules[0].ident, 0x00091F84u);
    EXPECT_EQ(r.cat.modules[0].pdos[0].entries[0].name, "DI1");
}

TEST(EsiOk, NumbersAsEsiFilesWriteThem) {
    uint64_t v = 0;
    EXPECT_TRUE(parse_esi_number("#x1A00", v) && v == 0x1a00);
    EXPECT_TRUE(parse_esi_number("#X1A00", v) && v == 0x1a00) << "upper-case #X, as some ESI files write it";
    EXPECT_TRUE(parse_esi_number(" #x10", v) && v == 0x10);
    EXPECT_TRUE(parse_esi_number("0x1a00", v) && v == 0x1a00);
    EXPECT_TRUE(parse_esi_number(" 6656 ", v) && v == 6656);
    EXPECT_FALSE(parse_esi_number("#x", v));
    EXPECT_FALSE(parse_esi_number("-1", v));
    EXPECT_FALSE(parse_esi_number("1a00", v));
    EXPECT_FALSE(parse_esi_number("", v));
}

TEST(EsiLoad, BrokenFileInAFolderLoadsNothing) {
    Catalogue cat;
    std::ostringstream err;
    EXPECT_FALSE(load_catalogue({source_path("tests/esi_ok"), source_path("tests/esi_err/bad_number.xml")}, cat, err));
    EXPECT_TRUE(contains(err.str(), "bad_number.xml:6: error: ProductCode is not a number")) << err.str();
    EXPECT_TRUE(cat.devices.empty());
}

// ESI, ENI and design files share the reader: a file cut short is reported on
// its last line, not on the line after it that libxml2 counts.
TEST(EsiLoad, CutShortReportedOnItsLastLine) {
    Diagnostics d;
    EXPECT_EQ(read_untrusted_xml("<EtherCATInfo>\n  <Vendor>\n", "ESI files", d), nullptr);
    EXPECT_EQ(d.format("e.xml"), "e.xml:2: error: XML is not well-formed: Premature end of data in tag Vendor line 2\n");
}

TEST(EsiLoad, MissingFileAndEmptyFolder) {
    Catalogue cat;
    std::ostringstream err;
    EXPECT_FALSE(load_catalogue({"/nonexistent/esi.xml"}, cat, err));
    EXPECT_TRUE(contains(err.str(), "/nonexistent/esi.xml: error: cannot read the ESI file")) << err.str();
    std::ostringstream err2;
    EXPECT_FALSE(load_catalogue({source_path("tests/unit")}, cat, err2));
    EXPECT_TRUE(contains(err2.str(), "holds no *.xml ESI files")) << err2.str();
}

// --- broken files: tests/esi_err -------------------------------------------

std::vector<std::string> xml_files(const std::string& folder) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(source_path(folder), ec))
        if (e.path().extension() == ".xml") names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// "<!-- expect: LINE: error: TEXT -->" on line 1 -> "FILE:LINE: error: " and TEXT.
std::pair<std::string, std::string> expectation(const std::string& content) {
    static const std::regex expect(R"(^<!--\s*expect:\s*(\d+):\s*error:\s*(.*?)\s*-->)");
    std::smatch m;
    std::string first = content.substr(0, content.find('\n'));
    if (!std::regex_search(first, m, expect)) return {};
    return {"input.xml:" + m[1].str() + ": error: ", m[2].str()};
}

bool has_line(const std::string& messages, const std::pair<std::string, std::string>& e) {
    std::istringstream in(messages);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(e.first, 0) == 0 && contains(line, e.second)) return true;
    return false;
}

class EsiErr : public ::testing::TestWithParam<std::string> {};

TEST_P(EsiErr, ReportsTheExpectedError) {
    const std::string content = read_file(source_path("tests/esi_err/" + GetParam()));
    auto e = expectation(content);
    ASSERT_FALSE(e.first.empty()) << GetParam() << ": line 1 must be <!-- expect: LINE: error: TEXT -->";
    Catalogue cat;
    Diagnostics diags;
    EXPECT_FALSE(read_esi(content, GetParam(), cat, diags));
    EXPECT_TRUE(cat.devices.empty() && cat.modules.empty()) << "a broken file adds nothing";
    EXPECT_TRUE(has_line(diags.format("input.xml"), e)) << "expected " << e.first << "..." << e.second
                                                        << "\ngot:\n" << diags.format("input.xml");
}

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = fs::path(info.param).stem().string();
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

INSTANTIATE_TEST_SUITE_P(Files, EsiErr, ::testing::ValuesIn(xml_files("tests/esi_err")), param_name);

TEST(EsiErrFolder, HasTheCases) { EXPECT_GE(xml_files("tests/esi_err").size(), 12u); }

}  // namespace
}  // namespace dissgen::testing
