-- SPDX-License-Identifier: GPL-2.0-or-later
-- EtherCAT datagrams as a Wireshark user would write them in Lua: the baseline that
-- bench/bench.py compares the dissgen plugin with. Same fields as rules/ethercat.xml
-- (header length/reserved/type, then datagrams until one has M = 0, inside the header's
-- Length), a "Datagram: CMD len N" tree text and the Info column.
--
-- Protocol "ecatlua"; registered on ethertype 0x88a4 and UDP port 34980, so that
-- `-d ethertype==0x88a4,ecatlua -d udp.port==34980,ecatlua` selects it whatever else is loaded.

local p = Proto("ecatlua", "EtherCAT (Lua)")

local cmd_names = {
    [0x00] = "NOP", [0x01] = "APRD", [0x02] = "APWR", [0x03] = "APRW", [0x04] = "FPRD",
    [0x05] = "FPWR", [0x06] = "FPRW", [0x07] = "BRD", [0x08] = "BWR", [0x09] = "BRW",
    [0x0a] = "LRD", [0x0b] = "LWR", [0x0c] = "LRW", [0x0d] = "ARMW", [0x0e] = "FRMW",
}
local type_names = { [1] = "EtherCAT datagrams", [4] = "Network variables", [5] = "Mailbox" }

local f_header   = ProtoField.none("ecatlua.header", "Header")
local f_hlength  = ProtoField.uint16("ecatlua.header.length", "Length", base.DEC, nil, 0x07ff)
local f_hres     = ProtoField.uint16("ecatlua.header.reserved", "Reserved", base.DEC, nil, 0x0800)
local f_htype    = ProtoField.uint16("ecatlua.header.type", "Type", base.DEC, type_names, 0xf000)
local f_datagram = ProtoField.none("ecatlua.datagram", "Datagram")
local f_cmd      = ProtoField.uint8("ecatlua.datagram.cmd", "Command", base.HEX, cmd_names)
local f_idx      = ProtoField.uint8("ecatlua.datagram.idx", "Index", base.HEX)
local f_adp      = ProtoField.uint16("ecatlua.datagram.adp", "Slave address (ADP)", base.HEX)
local f_ado      = ProtoField.uint16("ecatlua.datagram.ado", "Offset address (ADO)", base.HEX)
local f_lad      = ProtoField.uint32("ecatlua.datagram.lad", "Logical address", base.HEX)
local f_len      = ProtoField.uint16("ecatlua.datagram.len", "Length", base.DEC, nil, 0x07ff)
local f_res      = ProtoField.uint16("ecatlua.datagram.reserved", "Reserved", base.DEC, nil, 0x3800)
local f_circ     = ProtoField.bool("ecatlua.datagram.circulating", "Circulating", 16, nil, 0x4000)
local f_more     = ProtoField.bool("ecatlua.datagram.more", "More", 16, nil, 0x8000)
local f_irq      = ProtoField.uint16("ecatlua.datagram.irq", "Interrupt", base.HEX)
local f_data     = ProtoField.bytes("ecatlua.datagram.data", "Data")
local f_wkc      = ProtoField.uint16("ecatlua.datagram.wkc", "Working counter", base.DEC)
local f_payload  = ProtoField.bytes("ecatlua.payload", "Payload")

p.fields = { f_header, f_hlength, f_hres, f_htype, f_datagram, f_cmd, f_idx, f_adp, f_ado, f_lad,
             f_len, f_res, f_circ, f_more, f_irq, f_data, f_wkc, f_payload }

local e_truncated = ProtoExpert.new("ecatlua.truncated", "Truncated datagram",
                                    expert.group.MALFORMED, expert.severity.ERROR)
p.experts = { e_truncated }

local band, rshift = bit32.band, bit32.rshift

function p.dissector(tvb, pinfo, tree)
    local n = tvb:len()
    if n < 2 then return 0 end
    pinfo.cols.protocol = "ECATL"
    local root = tree:add(p, tvb())

    local h = tvb(0, 2):le_uint()
    local header = root:add(f_header, tvb(0, 2))
    header:add_le(f_hlength, tvb(0, 2))
    header:add_le(f_hres, tvb(0, 2))
    header:add_le(f_htype, tvb(0, 2))
    local length, ftype = band(h, 0x07ff), rshift(h, 12)
    local stop = math.min(2 + length, n)

    if ftype ~= 1 then
        if stop > 2 then root:add(f_payload, tvb(2, stop - 2)) end
        pinfo.cols.info = "EtherCAT"
        return n
    end

    local info = {}
    local off = 2
    repeat
        if off + 10 > stop then
            root:add_proto_expert_info(e_truncated)
            break
        end
        local cmd = tvb(off, 1):uint()
        local word = tvb(off + 6, 2):le_uint()
        local dlen = band(word, 0x07ff)
        local more = band(word, 0x8000) ~= 0
        local size = 12 + dlen
        local d = root:add(f_datagram, tvb(off, math.min(size, stop - off)))
        d:add(f_cmd, tvb(off, 1))
        d:add(f_idx, tvb(off + 1, 1))
        if cmd >= 0x0a and cmd <= 0x0c then
            d:add_le(f_lad, tvb(off + 2, 4))
        else
            d:add_le(f_adp, tvb(off + 2, 2))
            d:add_le(f_ado, tvb(off + 4, 2))
        end
        local lw = tvb(off + 6, 2)
        d:add_le(f_len, lw)
        d:add_le(f_res, lw)
        d:add_le(f_circ, lw)
        d:add_le(f_more, lw)
        d:add_le(f_irq, tvb(off + 8, 2))
        local text = (cmd_names[cmd] or string.format("Unknown (0x%x)", cmd)) .. " len " .. dlen
        d:append_text(": " .. text)
        info[#info + 1] = text
        if off + size > stop then
            d:add_proto_expert_info(e_truncated)
            break
        end
        if dlen > 0 then d:add(f_data, tvb(off + 10, dlen)) end
        d:add_le(f_wkc, tvb(off + 10 + dlen, 2))
        off = off + size
    until not more or off >= stop

    if #info > 1 then
        pinfo.cols.info = "Datagram \195\151" .. #info .. ": " .. table.concat(info, ", ")
    elseif #info == 1 then
        pinfo.cols.info = info[1]
    else
        pinfo.cols.info = "EtherCAT"
    end
    return n
end

DissectorTable.get("ethertype"):add(0x88a4, p)
DissectorTable.get("udp.port"):add(34980, p)
