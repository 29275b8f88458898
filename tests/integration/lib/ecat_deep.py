#!/usr/bin/env python3
"""Register and mailbox part of the EtherCAT differential (used by ecat_differential.py).

Every value Wireshark's ecat/ecat_mailbox plugin shows inside a datagram's data (ESC registers,
FMMU, SyncManager, DC, mailbox header, CoE, EoE, FoE, SoE) must be shown by ours at the same
bytes with the same value, unless Wireshark is wrong there (KNOWN_WRONG below, each with its
reason).  Both sides are read from tshark -T json -x: every field's "_raw" entry gives its
position and length in the frame, so a value is matched to ours by (field, position), not by
order.  DEEP_MAP names, for each Wireshark field, our field(s) for the same bytes and how to
compare them:
  value      the shown values are equal (integers compared modulo the field's width, so that a
             signed or a time display of the same bits agrees; strings and bytes as text)
  container  Wireshark shows the register as a number with its bits below it, ours as a
             container with the bits as fields: ours must have the container at the same bytes
  bitN       Wireshark shows one bit of a multi-bit field of ours (N: the bit)
  x32        Wireshark shows the value times 32 (EoE fragment offset in bytes, ours in its units)
  ipv4, text an address or a name, shown by ours as text or as its bytes
"""

import json
import re
from collections import defaultdict
from decimal import Decimal, InvalidOperation

from tshark_env import read_tshark_output

# Wireshark field -> ((our fields, any of which may be at the same bytes), how to compare)
DEEP_MAP = {
    'ecat.fmmu': (('ecatr.datagram.reg.fmmu',), 'container'),
    'ecat.fmmu.activate': (('ecatr.datagram.reg.fmmu.activate',), 'container'),
    'ecat.fmmu.activate0': (('ecatr.datagram.reg.fmmu.activate.activate0',), 'value'),
    'ecat.fmmu.lendbit': (('ecatr.datagram.reg.fmmu.lendbit',), 'value'),
    'ecat.fmmu.llen': (('ecatr.datagram.reg.fmmu.llen',), 'value'),
    'ecat.fmmu.lstart': (('ecatr.datagram.reg.fmmu.lstart',), 'value'),
    'ecat.fmmu.lstartbit': (('ecatr.datagram.reg.fmmu.lstartbit',), 'value'),
    'ecat.fmmu.pstart': (('ecatr.datagram.reg.fmmu.pstart',), 'value'),
    'ecat.fmmu.pstartbit': (('ecatr.datagram.reg.fmmu.pstartbit',), 'value'),
    'ecat.fmmu.type': (('ecatr.datagram.reg.fmmu.type',), 'container'),
    'ecat.fmmu.typeread': (('ecatr.datagram.reg.fmmu.type.typeread',), 'value'),
    'ecat.fmmu.typewrite': (('ecatr.datagram.reg.fmmu.type.typewrite',), 'value'),
    'ecat.reg.accessprotect': (('ecatr.datagram.reg.accessprotect',), 'value'),
    'ecat.reg.addrh': (('ecatr.datagram.reg.addrh',), 'value'),
    'ecat.reg.addrl': (('ecatr.datagram.reg.addrl',), 'value'),
    'ecat.reg.alctrl': (('ecatr.datagram.reg.alctrl',), 'container'),
    'ecat.reg.alctrl.ctrl': (('ecatr.datagram.reg.alctrl.ctrl',), 'value'),
    'ecat.reg.alctrl.errack': (('ecatr.datagram.reg.alctrl.errack',), 'value'),
    'ecat.reg.alctrl.id': (('ecatr.datagram.reg.alctrl.id',), 'value'),
    'ecat.reg.alstatus': (('ecatr.datagram.reg.alstatus',), 'container'),
    'ecat.reg.alstatus.err': (('ecatr.datagram.reg.alstatus.err',), 'value'),
    'ecat.reg.alstatus.id': (('ecatr.datagram.reg.alstatus.id',), 'value'),
    'ecat.reg.alstatus.status': (('ecatr.datagram.reg.alstatus.status',), 'value'),
    'ecat.reg.alstatuscode': (('ecatr.datagram.reg.alstatuscode',), 'value'),
    'ecat.reg.build': (('ecatr.datagram.reg.build',), 'value'),
    'ecat.reg.crc.fwd0': (('ecatr.datagram.reg.fwd0',), 'value'),
    'ecat.reg.crc.fwd1': (('ecatr.datagram.reg.fwd1',), 'value'),
    'ecat.reg.crc.fwd2': (('ecatr.datagram.reg.fwd2',), 'value'),
    'ecat.reg.crc.fwd3': (('ecatr.datagram.reg.fwd3',), 'value'),
    'ecat.reg.crc0': (('ecatr.datagram.reg.crc0',), 'container'),
    'ecat.reg.crc0.frame': (('ecatr.datagram.reg.crc0.frame',), 'value'),
    'ecat.reg.crc0.rx': (('ecatr.datagram.reg.crc0.rx',), 'value'),
    'ecat.reg.crc1': (('ecatr.datagram.reg.crc1',), 'container'),
    'ecat.reg.crc1.frame': (('ecatr.datagram.reg.crc1.frame',), 'value'),
    'ecat.reg.crc1.rx': (('ecatr.datagram.reg.crc1.rx',), 'value'),
    'ecat.reg.crc2': (('ecatr.datagram.reg.crc2',), 'container'),
    'ecat.reg.crc2.frame': (('ecatr.datagram.reg.crc2.frame',), 'value'),
    'ecat.reg.crc2.rx': (('ecatr.datagram.reg.crc2.rx',), 'value'),
    'ecat.reg.crc3': (('ecatr.datagram.reg.crc3',), 'container'),
    'ecat.reg.crc3.frame': (('ecatr.datagram.reg.crc3.frame',), 'value'),
    'ecat.reg.crc3.rx': (('ecatr.datagram.reg.crc3.rx',), 'value'),
    'ecat.reg.ctrlstat': (('ecatr.datagram.reg.ctrlstat',), 'container'),
    'ecat.reg.ctrlstat.2bacc': (('ecatr.datagram.reg.ctrlstat.bacc2',), 'value'),
    'ecat.reg.ctrlstat.8bacc': (('ecatr.datagram.reg.ctrlstat.bacc8',), 'value'),
    'ecat.reg.ctrlstat.busy': (('ecatr.datagram.reg.ctrlstat.busy',), 'value'),
    'ecat.reg.ctrlstat.cmderr': (('ecatr.datagram.reg.ctrlstat.cmderr',), 'value'),
    'ecat.reg.ctrlstat.crcerr': (('ecatr.datagram.reg.ctrlstat.crcerr',), 'value'),
    'ecat.reg.ctrlstat.eepromemul': (('ecatr.datagram.reg.ctrlstat.eepromemul',), 'value'),
    'ecat.reg.ctrlstat.lderr': (('ecatr.datagram.reg.ctrlstat.lderr',), 'value'),
    'ecat.reg.ctrlstat.rdacc': (('ecatr.datagram.reg.ctrlstat.rdacc',), 'value'),
    'ecat.reg.ctrlstat.reloadacc': (('ecatr.datagram.reg.ctrlstat.reloadacc',), 'value'),
    'ecat.reg.ctrlstat.wracc': (('ecatr.datagram.reg.ctrlstat.wracc',), 'value'),
    'ecat.reg.ctrlstat.wraccess': (('ecatr.datagram.reg.ctrlstat.wraccess',), 'value'),
    'ecat.reg.ctrlstat.wrerr': (('ecatr.datagram.reg.ctrlstat.wrerr',), 'value'),
    'ecat.reg.data0': (('ecatr.datagram.reg.data0',), 'value'),
    'ecat.reg.data1': (('ecatr.datagram.reg.data1',), 'value'),
    'ecat.reg.data2': (('ecatr.datagram.reg.data2',), 'value'),
    'ecat.reg.data3': (('ecatr.datagram.reg.data3',), 'value'),
    'ecat.reg.dc.activation': (('ecatr.datagram.reg.activation',), 'container'),
    'ecat.reg.dc.activation.autoactivation': (('ecatr.datagram.reg.activation.autoactivation',), 'value'),
    'ecat.reg.dc.activation.dblrange': (('ecatr.datagram.reg.activation.dblrange',), 'value'),
    'ecat.reg.dc.activation.enablecyclic': (('ecatr.datagram.reg.activation.enablecyclic',), 'value'),
    'ecat.reg.dc.activation.gen_sync0': (('ecatr.datagram.reg.activation.gen_sync0',), 'value'),
    'ecat.reg.dc.activation.gen_sync1': (('ecatr.datagram.reg.activation.gen_sync1',), 'value'),
    'ecat.reg.dc.activation.hlfrange': (('ecatr.datagram.reg.activation.hlfrange',), 'value'),
    'ecat.reg.dc.activation.stimecheck': (('ecatr.datagram.reg.activation.stimecheck',), 'value'),
    'ecat.reg.dc.activation.stimeext': (('ecatr.datagram.reg.activation.stimeext',), 'value'),
    'ecat.reg.dc.activationstat': (('ecatr.datagram.reg.activationstat',), 'container'),
    'ecat.reg.dc.activationstat.stimeoutofrange': (('ecatr.datagram.reg.activationstat.stimeoutofrange',), 'value'),
    'ecat.reg.dc.activationstat.sync0pend': (('ecatr.datagram.reg.activationstat.sync0pend',), 'value'),
    'ecat.reg.dc.activationstat.sync1pend': (('ecatr.datagram.reg.activationstat.sync1pend',), 'value'),
    'ecat.reg.dc.ctrlerr': (('ecatr.datagram.reg.ctrlerr',), 'container'),
    'ecat.reg.dc.cycimpuls': (('ecatr.datagram.reg.cycimpuls',), 'value'),
    'ecat.reg.dc.cyctime0': (('ecatr.datagram.reg.cyctime0',), 'value'),
    'ecat.reg.dc.cyctime1': (('ecatr.datagram.reg.cyctime1',), 'value'),
    'ecat.reg.dc.cycunitctrl': (('ecatr.datagram.reg.cycunitctrl',), 'container'),
    'ecat.reg.dc.cycunitctrl.access_cyclic': (('ecatr.datagram.reg.cycunitctrl.access_cyclic',), 'value'),
    'ecat.reg.dc.cycunitctrl.access_latch0': (('ecatr.datagram.reg.cycunitctrl.access_latch0',), 'value'),
    'ecat.reg.dc.cycunitctrl.access_latch1': (('ecatr.datagram.reg.cycunitctrl.access_latch1',), 'value'),
    'ecat.reg.dc.fltdepth.speedcnt': (('ecatr.datagram.reg.fltdepth_speedcnt',), 'value'),
    'ecat.reg.dc.fltdepth.systimediff': (('ecatr.datagram.reg.fltdepth_systimediff',), 'value'),
    'ecat.reg.dc.latch0.ctrl': (('ecatr.datagram.reg.latch0_ctrl',), 'container'),
    'ecat.reg.dc.latch0.ctrl.neg': (('ecatr.datagram.reg.latch0_ctrl.neg',), 'value'),
    'ecat.reg.dc.latch0.ctrl.pos': (('ecatr.datagram.reg.latch0_ctrl.pos',), 'value'),
    'ecat.reg.dc.latch0.neg': (('ecatr.datagram.reg.latch0_neg',), 'value'),
    'ecat.reg.dc.latch0.pos': (('ecatr.datagram.reg.latch0_pos',), 'value'),
    'ecat.reg.dc.latch0.status': (('ecatr.datagram.reg.latch0_status',), 'container'),
    'ecat.reg.dc.latch0.status.eventneg': (('ecatr.datagram.reg.latch0_status.eventneg',), 'value'),
    'ecat.reg.dc.latch0.status.eventpos': (('ecatr.datagram.reg.latch0_status.eventpos',), 'value'),
    'ecat.reg.dc.latch0.status.pinstate': (('ecatr.datagram.reg.latch0_status.pinstate',), 'value'),
    'ecat.reg.dc.latch1.ctrl': (('ecatr.datagram.reg.latch1_ctrl',), 'container'),
    'ecat.reg.dc.latch1.ctrl.neg': (('ecatr.datagram.reg.latch1_ctrl.neg',), 'value'),
    'ecat.reg.dc.latch1.ctrl.pos': (('ecatr.datagram.reg.latch1_ctrl.pos',), 'value'),
    'ecat.reg.dc.latch1.neg': (('ecatr.datagram.reg.latch1_neg',), 'value'),
    'ecat.reg.dc.latch1.pos': (('ecatr.datagram.reg.latch1_pos',), 'value'),
    'ecat.reg.dc.latch1.status': (('ecatr.datagram.reg.latch1_status',), 'container'),
    'ecat.reg.dc.latch1.status.eventneg': (('ecatr.datagram.reg.latch1_status.eventneg',), 'value'),
    'ecat.reg.dc.latch1.status.eventpos': (('ecatr.datagram.reg.latch1_status.eventpos',), 'value'),
    'ecat.reg.dc.latch1.status.pinstate': (('ecatr.datagram.reg.latch1_status.pinstate',), 'value'),
    'ecat.reg.dc.pdismchg': (('ecatr.datagram.reg.pdismchg',), 'value'),
    'ecat.reg.dc.pdismstart': (('ecatr.datagram.reg.pdismstart',), 'value'),
    'ecat.reg.dc.rcvsyncmanchg': (('ecatr.datagram.reg.rcvsyncmanchg',), 'value'),
    'ecat.reg.dc.recv0': (('ecatr.datagram.reg.recv0',), 'value'),
    'ecat.reg.dc.recv1': (('ecatr.datagram.reg.recv1',), 'value'),
    'ecat.reg.dc.recv2': (('ecatr.datagram.reg.recv2',), 'value'),
    'ecat.reg.dc.recv3': (('ecatr.datagram.reg.recv3',), 'value'),
    'ecat.reg.dc.recvtime64': (('ecatr.datagram.reg.recvtime64',), 'value'),
    'ecat.reg.dc.speeddiff': (('ecatr.datagram.reg.speeddiff',), 'value'),
    'ecat.reg.dc.speedstart': (('ecatr.datagram.reg.speedstart',), 'value'),
    'ecat.reg.dc.starttime0': (('ecatr.datagram.reg.starttime0',), 'value'),
    'ecat.reg.dc.starttime1': (('ecatr.datagram.reg.starttime1',), 'value'),
    'ecat.reg.dc.sync0.status': (('ecatr.datagram.reg.sync0_status',), 'container'),
    'ecat.reg.dc.sync0.status.triggered': (('ecatr.datagram.reg.sync0_status.triggered',), 'value'),
    'ecat.reg.dc.sync1.status': (('ecatr.datagram.reg.sync1_status',), 'container'),
    'ecat.reg.dc.sync1.status.triggered': (('ecatr.datagram.reg.sync1_status.triggered',), 'value'),
    'ecat.reg.dc.systime': (('ecatr.datagram.reg.systime',), 'value'),
    'ecat.reg.dc.systimeH': (('ecatr.datagram.reg.systimeh',), 'value'),
    'ecat.reg.dc.systimeL': (('ecatr.datagram.reg.systimel',), 'value'),
    'ecat.reg.dc.systimedelay': (('ecatr.datagram.reg.systimedelay',), 'value'),
    'ecat.reg.dc.systimeoffs': (('ecatr.datagram.reg.systimeoffs',), 'value'),
    'ecat.reg.dc.systimeoffsh': (('ecatr.datagram.reg.systimeoffsh',), 'value'),
    'ecat.reg.dc.systimeoffsl': (('ecatr.datagram.reg.systimeoffsl',), 'value'),
    'ecat.reg.dlcrtl2': (('ecatr.datagram.reg.dlcrtl2',), 'container'),
    'ecat.reg.dlcrtl2.port0': (('ecatr.datagram.reg.dlcrtl2.port0',), 'value'),
    'ecat.reg.dlcrtl2.port1': (('ecatr.datagram.reg.dlcrtl2.port1',), 'value'),
    'ecat.reg.dlcrtl2.port2': (('ecatr.datagram.reg.dlcrtl2.port2',), 'value'),
    'ecat.reg.dlcrtl2.port3': (('ecatr.datagram.reg.dlcrtl2.port3',), 'value'),
    'ecat.reg.dlctrl1': (('ecatr.datagram.reg.dlctrl1',), 'container'),
    'ecat.reg.dlctrl1.killnonecat': (('ecatr.datagram.reg.dlctrl1.killnonecat',), 'value'),
    'ecat.reg.dlctrl1.port0extlinkdetect': (('ecatr.datagram.reg.dlctrl1.port0extlinkdetect',), 'value'),
    'ecat.reg.dlctrl1.port1extlinkdetect': (('ecatr.datagram.reg.dlctrl1.port1extlinkdetect',), 'value'),
    'ecat.reg.dlctrl1.port2extlinkdetect': (('ecatr.datagram.reg.dlctrl1.port2extlinkdetect',), 'value'),
    'ecat.reg.dlctrl1.port3extlinkdetect': (('ecatr.datagram.reg.dlctrl1.port3extlinkdetect',), 'value'),
    'ecat.reg.dlctrl3': (('ecatr.datagram.reg.dlctrl3',), 'container'),
    'ecat.reg.dlctrl3.fifosize': (('ecatr.datagram.reg.dlctrl3.fifosize',), 'value'),
    'ecat.reg.dlctrl3.lowebusjit': (('ecatr.datagram.reg.dlctrl3.lowebusjit',), 'value'),
    'ecat.reg.dlctrl4': (('ecatr.datagram.reg.dlctrl4',), 'container'),
    'ecat.reg.dlctrl4.2ndaddress': (('ecatr.datagram.reg.dlctrl4.alias2nd',), 'value'),
    'ecat.reg.dlstatus1': (('ecatr.datagram.reg.dlstatus1',), 'container'),
    'ecat.reg.dlstatus1.enhlinkdetect': (('ecatr.datagram.reg.dlstatus1.enhlinkdetect',), 'value'),
    'ecat.reg.dlstatus1.operation': (('ecatr.datagram.reg.dlstatus1.operation',), 'value'),
    'ecat.reg.dlstatus1.pdiwatchdog': (('ecatr.datagram.reg.dlstatus1.pdiwatchdog',), 'value'),
    'ecat.reg.dlstatus1.physlink.port0': (('ecatr.datagram.reg.dlstatus1.physlink_port0',), 'value'),
    'ecat.reg.dlstatus1.physlink.port1': (('ecatr.datagram.reg.dlstatus1.physlink_port1',), 'value'),
    'ecat.reg.dlstatus1.physlink.port2': (('ecatr.datagram.reg.dlstatus1.physlink_port2',), 'value'),
    'ecat.reg.dlstatus1.physlink.port3': (('ecatr.datagram.reg.dlstatus1.physlink_port3',), 'value'),
    'ecat.reg.dlstatus2': (('ecatr.datagram.reg.dlstatus2',), 'container'),
    'ecat.reg.dlstatus2.port0': (('ecatr.datagram.reg.dlstatus2.port0',), 'value'),
    'ecat.reg.dlstatus2.port1': (('ecatr.datagram.reg.dlstatus2.port1',), 'value'),
    'ecat.reg.dlstatus2.port2': (('ecatr.datagram.reg.dlstatus2.port2',), 'value'),
    'ecat.reg.dlstatus2.port3': (('ecatr.datagram.reg.dlstatus2.port3',), 'value'),
    'ecat.reg.dpram': (('ecatr.datagram.reg.portdesc',), 'container'),
    'ecat.reg.eeprom.assign': (('ecatr.datagram.reg.eeprom_assign',), 'container'),
    'ecat.reg.eeprom.assign.ctrl': (('ecatr.datagram.reg.eeprom_assign.ctrl',), 'value'),
    'ecat.reg.eeprom.assign.pdiaccess': (('ecatr.datagram.reg.eeprom_assign.pdiaccess',), 'value'),
    'ecat.reg.eeprom.assign.status': (('ecatr.datagram.reg.eeprom_assign.status',), 'value'),
    'ecat.reg.features': (('ecatr.datagram.reg.features',), 'container'),
    'ecat.reg.features.crcext': (('ecatr.datagram.reg.features.crcext',), 'value'),
    'ecat.reg.features.dc64support': (('ecatr.datagram.reg.features.dc64support',), 'value'),
    'ecat.reg.features.dcsupport': (('ecatr.datagram.reg.features.dcsupport',), 'value'),
    'ecat.reg.features.ebusextlinkdetect': (('ecatr.datagram.reg.features.ebusextlinkdetect',), 'value'),
    'ecat.reg.features.ebuslowjitter': (('ecatr.datagram.reg.features.ebuslowjitter',), 'value'),
    'ecat.reg.features.fmmurestrict': (('ecatr.datagram.reg.features.fmmurestrict',), 'value'),
    'ecat.reg.features.miiextlinkdetect': (('ecatr.datagram.reg.features.miiextlinkdetect',), 'value'),
    'ecat.reg.features.smaddrrestrict': (('ecatr.datagram.reg.features.smaddrrestrict',), 'value'),
    'ecat.reg.fmmucnt': (('ecatr.datagram.reg.fmmucnt',), 'value'),
    'ecat.reg.irq.ecat': (('ecatr.datagram.reg.irq_ecat',), 'container'),
    'ecat.reg.irq.ecat.alstatevt': (('ecatr.datagram.reg.irq_ecat.alstatevt',), 'value'),
    'ecat.reg.irq.ecat.escstatevt': (('ecatr.datagram.reg.irq_ecat.escstatevt',), 'value'),
    'ecat.reg.irq.ecat.latchevt': (('ecatr.datagram.reg.irq_ecat.latchevt',), 'value'),
    'ecat.reg.irq.ecat.sm0irq': (('ecatr.datagram.reg.irq_ecat.sm0irq',), 'value'),
    'ecat.reg.irq.ecat.sm1irq': (('ecatr.datagram.reg.irq_ecat.sm1irq',), 'value'),
    'ecat.reg.irq.ecat.sm2irq': (('ecatr.datagram.reg.irq_ecat.sm2irq',), 'value'),
    'ecat.reg.irq.ecat.sm3irq': (('ecatr.datagram.reg.irq_ecat.sm3irq',), 'value'),
    'ecat.reg.irq.ecat.sm4irq': (('ecatr.datagram.reg.irq_ecat.sm4irq',), 'value'),
    'ecat.reg.irq.ecat.sm5irq': (('ecatr.datagram.reg.irq_ecat.sm5irq',), 'value'),
    'ecat.reg.irq.ecat.sm6irq': (('ecatr.datagram.reg.irq_ecat.sm6irq',), 'value'),
    'ecat.reg.irq.ecat.sm7irq': (('ecatr.datagram.reg.irq_ecat.sm7irq',), 'value'),
    'ecat.reg.irq.pdi1': (('ecatr.datagram.reg.irq_pdi1',), 'container'),
    'ecat.reg.irq.pdi1.alctrl': (('ecatr.datagram.reg.irq_pdi1.alctrl',), 'value'),
    'ecat.reg.irq.pdi1.eepromcmdpen': (('ecatr.datagram.reg.irq_pdi1.eepromcmdpen',), 'value'),
    'ecat.reg.irq.pdi1.latchin': (('ecatr.datagram.reg.irq_pdi1.latchin',), 'value'),
    'ecat.reg.irq.pdi1.sm0': (('ecatr.datagram.reg.irq_pdi1.sm0',), 'value'),
    'ecat.reg.irq.pdi1.sm1': (('ecatr.datagram.reg.irq_pdi1.sm1',), 'value'),
    'ecat.reg.irq.pdi1.sm2': (('ecatr.datagram.reg.irq_pdi1.sm2',), 'value'),
    'ecat.reg.irq.pdi1.sm3': (('ecatr.datagram.reg.irq_pdi1.sm3',), 'value'),
    'ecat.reg.irq.pdi1.sm4': (('ecatr.datagram.reg.irq_pdi1.sm4',), 'value'),
    'ecat.reg.irq.pdi1.sm5': (('ecatr.datagram.reg.irq_pdi1.sm5',), 'value'),
    'ecat.reg.irq.pdi1.sm6': (('ecatr.datagram.reg.irq_pdi1.sm6',), 'value'),
    'ecat.reg.irq.pdi1.sm7': (('ecatr.datagram.reg.irq_pdi1.sm7',), 'value'),
    'ecat.reg.irq.pdi1.smchg': (('ecatr.datagram.reg.irq_pdi1.smchg',), 'value'),
    'ecat.reg.irq.pdi1.sync0': (('ecatr.datagram.reg.irq_pdi1.sync0',), 'value'),
    'ecat.reg.irq.pdi1.sync1': (('ecatr.datagram.reg.irq_pdi1.sync1',), 'value'),
    'ecat.reg.irq.pdi2': (('ecatr.datagram.reg.irq_pdi2',), 'value'),
    'ecat.reg.irqmask.ecat_mask': (('ecatr.datagram.reg.ecat_mask',), 'container'),
    'ecat.reg.irqmask.ecat_mask.alstatevt': (('ecatr.datagram.reg.ecat_mask.alstatevt',), 'value'),
    'ecat.reg.irqmask.ecat_mask.escstatevt': (('ecatr.datagram.reg.ecat_mask.escstatevt',), 'value'),
    'ecat.reg.irqmask.ecat_mask.latchevt': (('ecatr.datagram.reg.ecat_mask.latchevt',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm0irq': (('ecatr.datagram.reg.ecat_mask.sm0irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm1irq': (('ecatr.datagram.reg.ecat_mask.sm1irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm2irq': (('ecatr.datagram.reg.ecat_mask.sm2irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm3irq': (('ecatr.datagram.reg.ecat_mask.sm3irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm4irq': (('ecatr.datagram.reg.ecat_mask.sm4irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm5irq': (('ecatr.datagram.reg.ecat_mask.sm5irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm6irq': (('ecatr.datagram.reg.ecat_mask.sm6irq',), 'value'),
    'ecat.reg.irqmask.ecat_mask.sm7irq': (('ecatr.datagram.reg.ecat_mask.sm7irq',), 'value'),
    'ecat.reg.irqmask.pdiH': (('ecatr.datagram.reg.pdih',), 'value'),
    'ecat.reg.irqmask.pdiL': (('ecatr.datagram.reg.pdil',), 'container'),
    'ecat.reg.irqmask.pdiL.alctrl': (('ecatr.datagram.reg.pdil.alctrl',), 'value'),
    'ecat.reg.irqmask.pdiL.eepromcmdpen': (('ecatr.datagram.reg.pdil.eepromcmdpen',), 'value'),
    'ecat.reg.irqmask.pdiL.latchin': (('ecatr.datagram.reg.pdil.latchin',), 'value'),
    'ecat.reg.irqmask.pdiL.sm0': (('ecatr.datagram.reg.pdil.sm0',), 'value'),
    'ecat.reg.irqmask.pdiL.sm1': (('ecatr.datagram.reg.pdil.sm1',), 'value'),
    'ecat.reg.irqmask.pdiL.sm2': (('ecatr.datagram.reg.pdil.sm2',), 'value'),
    'ecat.reg.irqmask.pdiL.sm3': (('ecatr.datagram.reg.pdil.sm3',), 'value'),
    'ecat.reg.irqmask.pdiL.sm4': (('ecatr.datagram.reg.pdil.sm4',), 'value'),
    'ecat.reg.irqmask.pdiL.sm5': (('ecatr.datagram.reg.pdil.sm5',), 'value'),
    'ecat.reg.irqmask.pdiL.sm6': (('ecatr.datagram.reg.pdil.sm6',), 'value'),
    'ecat.reg.irqmask.pdiL.sm7': (('ecatr.datagram.reg.pdil.sm7',), 'value'),
    'ecat.reg.irqmask.pdiL.smchg': (('ecatr.datagram.reg.pdil.smchg',), 'value'),
    'ecat.reg.irqmask.pdiL.sync0': (('ecatr.datagram.reg.pdil.sync0',), 'value'),
    'ecat.reg.irqmask.pdiL.sync1': (('ecatr.datagram.reg.pdil.sync1',), 'value'),
    'ecat.reg.linklost0': (('ecatr.datagram.reg.linklost0',), 'value'),
    'ecat.reg.linklost1': (('ecatr.datagram.reg.linklost1',), 'value'),
    'ecat.reg.linklost2': (('ecatr.datagram.reg.linklost2',), 'value'),
    'ecat.reg.linklost3': (('ecatr.datagram.reg.linklost3',), 'value'),
    'ecat.reg.mio.access': (('ecatr.datagram.reg.mio_access',), 'container'),
    'ecat.reg.mio.access.ecatacc': (('ecatr.datagram.reg.mio_access.ecatacc',), 'value'),
    'ecat.reg.mio.access.forcereset': (('ecatr.datagram.reg.mio_access.forcereset',), 'value'),
    'ecat.reg.mio.access.pdiacc': (('ecatr.datagram.reg.mio_access.pdiacc',), 'value'),
    'ecat.reg.mio.addr': (('ecatr.datagram.reg.mio_addr',), 'container'),
    'ecat.reg.mio.addr.mioaddr': (('ecatr.datagram.reg.mio_addr.mioaddr',), 'value'),
    'ecat.reg.mio.addr.phyaddr': (('ecatr.datagram.reg.mio_addr.phyaddr',), 'value'),
    'ecat.reg.mio.ctrlstat': (('ecatr.datagram.reg.mio_ctrlstat',), 'container'),
    'ecat.reg.mio.ctrlstat.busy': (('ecatr.datagram.reg.mio_ctrlstat.busy',), 'value'),
    'ecat.reg.mio.ctrlstat.offsphy': (('ecatr.datagram.reg.mio_ctrlstat.offsphy',), 'value'),
    'ecat.reg.mio.ctrlstat.rdacc': (('ecatr.datagram.reg.mio_ctrlstat.rdacc',), 'value'),
    'ecat.reg.mio.ctrlstat.wracc1': (('ecatr.datagram.reg.mio_ctrlstat.wracc1',), 'value'),
    'ecat.reg.mio.ctrlstat.wracc2': (('ecatr.datagram.reg.mio_ctrlstat.wracc2',), 'value'),
    'ecat.reg.mio.ctrlstat.wrerr': (('ecatr.datagram.reg.mio_ctrlstat.wrerr',), 'value'),
    'ecat.reg.mio.data': (('ecatr.datagram.reg.mio_data',), 'value'),
    'ecat.reg.mio.status0': (('ecatr.datagram.reg.mio_status0',), 'container'),
    'ecat.reg.mio.status0.link': (('ecatr.datagram.reg.mio_status0.link',), 'value'),
    'ecat.reg.mio.status0.linkpartnererr': (('ecatr.datagram.reg.mio_status0.linkpartnererr',), 'value'),
    'ecat.reg.mio.status0.linkstatuserr': (('ecatr.datagram.reg.mio_status0.linkstatuserr',), 'value'),
    'ecat.reg.mio.status0.phycfgupdated': (('ecatr.datagram.reg.mio_status0.phycfgupdated',), 'value'),
    'ecat.reg.mio.status0.physlink': (('ecatr.datagram.reg.mio_status0.physlink',), 'value'),
    'ecat.reg.mio.status0.readerr': (('ecatr.datagram.reg.mio_status0.readerr',), 'value'),
    'ecat.reg.mio.status1': (('ecatr.datagram.reg.mio_status1',), 'container'),
    'ecat.reg.mio.status1.link': (('ecatr.datagram.reg.mio_status1.link',), 'value'),
    'ecat.reg.mio.status1.linkpartnererr': (('ecatr.datagram.reg.mio_status1.linkpartnererr',), 'value'),
    'ecat.reg.mio.status1.linkstatuserr': (('ecatr.datagram.reg.mio_status1.linkstatuserr',), 'value'),
    'ecat.reg.mio.status1.phycfgupdated': (('ecatr.datagram.reg.mio_status1.phycfgupdated',), 'value'),
    'ecat.reg.mio.status1.physlink': (('ecatr.datagram.reg.mio_status1.physlink',), 'value'),
    'ecat.reg.mio.status1.readerr': (('ecatr.datagram.reg.mio_status1.readerr',), 'value'),
    'ecat.reg.mio.status2': (('ecatr.datagram.reg.mio_status2',), 'container'),
    'ecat.reg.mio.status2.link': (('ecatr.datagram.reg.mio_status2.link',), 'value'),
    'ecat.reg.mio.status2.linkpartnererr': (('ecatr.datagram.reg.mio_status2.linkpartnererr',), 'value'),
    'ecat.reg.mio.status2.linkstatuserr': (('ecatr.datagram.reg.mio_status2.linkstatuserr',), 'value'),
    'ecat.reg.mio.status2.phycfgupdated': (('ecatr.datagram.reg.mio_status2.phycfgupdated',), 'value'),
    'ecat.reg.mio.status2.physlink': (('ecatr.datagram.reg.mio_status2.physlink',), 'value'),
    'ecat.reg.mio.status2.readerr': (('ecatr.datagram.reg.mio_status2.readerr',), 'value'),
    'ecat.reg.mio.status3': (('ecatr.datagram.reg.mio_status3',), 'container'),
    'ecat.reg.mio.status3.link': (('ecatr.datagram.reg.mio_status3.link',), 'value'),
    'ecat.reg.mio.status3.linkpartnererr': (('ecatr.datagram.reg.mio_status3.linkpartnererr',), 'value'),
    'ecat.reg.mio.status3.linkstatuserr': (('ecatr.datagram.reg.mio_status3.linkstatuserr',), 'value'),
    'ecat.reg.mio.status3.phycfgupdated': (('ecatr.datagram.reg.mio_status3.phycfgupdated',), 'value'),
    'ecat.reg.mio.status3.physlink': (('ecatr.datagram.reg.mio_status3.physlink',), 'value'),
    'ecat.reg.mio.status3.readerr': (('ecatr.datagram.reg.mio_status3.readerr',), 'value'),
    'ecat.reg.pdictrl1': (('ecatr.datagram.reg.pdictrl1',), 'container'),
    'ecat.reg.pdictrl1.pdi': (('ecatr.datagram.reg.pdictrl1.pdi',), 'value'),
    'ecat.reg.pdictrl2': (('ecatr.datagram.reg.pdictrl2',), 'container'),
    'ecat.reg.pdictrl2.dcsyncin': (('ecatr.datagram.reg.pdictrl2.dcsyncin',), 'value'),
    'ecat.reg.pdictrl2.dcsyncout': (('ecatr.datagram.reg.pdictrl2.dcsyncout',), 'value'),
    'ecat.reg.pdictrl2.devemul': (('ecatr.datagram.reg.pdictrl2.devemul',), 'value'),
    'ecat.reg.pdictrl2.enhlnkdetect': (('ecatr.datagram.reg.pdictrl2.enhlnkdetect',), 'value'),
    'ecat.reg.pdictrl2.enhlnkdetect0': (('ecatr.datagram.reg.pdictrl2.enhlnkdetect0',), 'value'),
    'ecat.reg.pdictrl2.enhlnkdetect1': (('ecatr.datagram.reg.pdictrl2.enhlnkdetect1',), 'value'),
    'ecat.reg.pdictrl2.enhlnkdetect2': (('ecatr.datagram.reg.pdictrl2.enhlnkdetect2',), 'value'),
    'ecat.reg.pdictrl2.enhlnkdetect3': (('ecatr.datagram.reg.pdictrl2.enhlnkdetect3',), 'value'),
    'ecat.reg.pdierr': (('ecatr.datagram.reg.pdierr',), 'value'),
    'ecat.reg.physaddr': (('ecatr.datagram.reg.physaddr',), 'value'),
    'ecat.reg.physaddr2': (('ecatr.datagram.reg.physaddr2',), 'value'),
    'ecat.reg.ports': (('ecatr.datagram.reg.ramsize',), 'value'),
    'ecat.reg.processuniterr': (('ecatr.datagram.reg.processuniterr',), 'value'),
    'ecat.reg.regprotect': (('ecatr.datagram.reg.regprotect',), 'value'),
    'ecat.reg.resetecat': (('ecatr.datagram.reg.resetecat',), 'value'),
    'ecat.reg.resetpdi': (('ecatr.datagram.reg.resetpdi',), 'value'),
    'ecat.reg.revision': (('ecatr.datagram.reg.revision',), 'value'),
    'ecat.reg.smcnt': (('ecatr.datagram.reg.smcnt',), 'value'),
    'ecat.reg.type': (('ecatr.datagram.reg.type',), 'value'),
    'ecat.reg.wd.cntpdi': (('ecatr.datagram.reg.wd_cntpdi',), 'value'),
    'ecat.reg.wd.cntsm': (('ecatr.datagram.reg.wd_cntsm',), 'value'),
    'ecat.reg.wd.divisor': (('ecatr.datagram.reg.wd_divisor',), 'value'),
    'ecat.reg.wd.status': (('ecatr.datagram.reg.wd_status',), 'container'),
    'ecat.reg.wd.status.pdwatchdog': (('ecatr.datagram.reg.wd_status.pdwatchdog',), 'value'),
    'ecat.reg.wd.timepdi': (('ecatr.datagram.reg.wd_timepdi',), 'value'),
    'ecat.reg.wd.timesm': (('ecatr.datagram.reg.wd_timesm',), 'value'),
    'ecat.regphysrwoffs': (('ecatr.datagram.reg.physrwoffs',), 'value'),
    'ecat.syncman': (('ecatr.datagram.reg.syncman',), 'container'),
    'ecat.syncman.1bufstate': (('ecatr.datagram.reg.syncman.ctrlstatus.bufstate1',), 'value'),
    'ecat.syncman.3bufstate': (('ecatr.datagram.reg.syncman.ctrlstatus.bufstate3',), 'value'),
    'ecat.syncman.access': (('ecatr.datagram.reg.syncman.ctrlstatus.access',), 'value'),
    'ecat.syncman.ctrlstatus': (('ecatr.datagram.reg.syncman.ctrlstatus',), 'container'),
    'ecat.syncman.deactivate': (('ecatr.datagram.reg.syncman.smenable.deactivate',), 'value'),
    'ecat.syncman.enable': (('ecatr.datagram.reg.syncman.smenable.enable',), 'value'),
    'ecat.syncman.irq.ecat': (('ecatr.datagram.reg.syncman.ctrlstatus.irq_ecat',), 'value'),
    'ecat.syncman.irq.pdi': (('ecatr.datagram.reg.syncman.ctrlstatus.irq_pdi',), 'value'),
    'ecat.syncman.irq.read': (('ecatr.datagram.reg.syncman.ctrlstatus.irq_read',), 'value'),
    'ecat.syncman.irq.write': (('ecatr.datagram.reg.syncman.ctrlstatus.irq_write',), 'value'),
    'ecat.syncman.latchsmchg.ecat': (('ecatr.datagram.reg.syncman.smenable.latchsmchg_ecat',), 'value'),
    'ecat.syncman.latchsmchg.pdi': (('ecatr.datagram.reg.syncman.smenable.latchsmchg_pdi',), 'value'),
    'ecat.syncman.len': (('ecatr.datagram.reg.syncman.len',), 'value'),
    'ecat.syncman.opmode': (('ecatr.datagram.reg.syncman.ctrlstatus.opmode',), 'value'),
    'ecat.syncman.repeatack': (('ecatr.datagram.reg.syncman.smenable.repeatack',), 'value'),
    'ecat.syncman.repeatreq': (('ecatr.datagram.reg.syncman.smenable.repeatreq',), 'value'),
    'ecat.syncman.smenable': (('ecatr.datagram.reg.syncman.smenable',), 'container'),
    'ecat.syncman.start': (('ecatr.datagram.reg.syncman.start',), 'value'),
    'ecat.syncman.wdt': (('ecatr.datagram.reg.syncman.ctrlstatus.wdt',), 'value'),
    'ecat_mailbox.address': (('ecatr.datagram.mbx.address',), 'value'),
    'ecat_mailbox.coe.abortcode': (('ecatr.datagram.mbx.coe.sdoreq.abortcode', 'ecatr.datagram.mbx.coe.sdores.abortcode'), 'value'),
    'ecat_mailbox.coe.dsoldata': (('ecatr.datagram.mbx.coe.sdoreq.normal.data', 'ecatr.datagram.mbx.coe.sdores.normal.data', 'ecatr.datagram.mbx.coe.sdoreq.segdata', 'ecatr.datagram.mbx.coe.sdores.segdata'), 'value'),
    'ecat_mailbox.coe.number': (('ecatr.datagram.mbx.coe.number',), 'value'),
    'ecat_mailbox.coe.sdoccsds': (('ecatr.datagram.mbx.coe.sdoreq.dlseg',), 'container'),
    'ecat_mailbox.coe.sdoccsds.lastseg': (('ecatr.datagram.mbx.coe.sdoreq.dlseg.lastseg',), 'value'),
    'ecat_mailbox.coe.sdoccsds.size': (('ecatr.datagram.mbx.coe.sdoreq.dlseg.size',), 'value'),
    'ecat_mailbox.coe.sdoccsds.toggle': (('ecatr.datagram.mbx.coe.sdoreq.dlseg.toggle',), 'value'),
    'ecat_mailbox.coe.sdoccsid': (('ecatr.datagram.mbx.coe.sdoreq.initdl',), 'container'),
    'ecat_mailbox.coe.sdoccsid.complete': (('ecatr.datagram.mbx.coe.sdoreq.initdl.complete', 'ecatr.datagram.mbx.coe.sdoreq.initul.complete'), 'value'),
    'ecat_mailbox.coe.sdoccsid.expedited': (('ecatr.datagram.mbx.coe.sdoreq.initdl.expedited',), 'value'),
    'ecat_mailbox.coe.sdoccsid.size0': (('ecatr.datagram.mbx.coe.sdoreq.initdl.size',), 'bit0'),
    'ecat_mailbox.coe.sdoccsid.size1': (('ecatr.datagram.mbx.coe.sdoreq.initdl.size',), 'bit1'),
    'ecat_mailbox.coe.sdoccsid.sizeind': (('ecatr.datagram.mbx.coe.sdoreq.initdl.sizeind',), 'value'),
    'ecat_mailbox.coe.sdoccsiu': (('ecatr.datagram.mbx.coe.sdoreq.initul',), 'container'),
    'ecat_mailbox.coe.sdoccsus': (('ecatr.datagram.mbx.coe.sdoreq.ulseg',), 'container'),
    'ecat_mailbox.coe.sdoccsus_toggle': (('ecatr.datagram.mbx.coe.sdoreq.ulseg.toggle',), 'value'),
    'ecat_mailbox.coe.sdodata': (('ecatr.datagram.mbx.coe.sdoreq.expedited.data', 'ecatr.datagram.mbx.coe.sdores.expedited.data'), 'value'),
    'ecat_mailbox.coe.sdoidx': (('ecatr.datagram.mbx.coe.sdoreq.index', 'ecatr.datagram.mbx.coe.sdores.index'), 'value'),
    'ecat_mailbox.coe.sdoinfobitlen': (('ecatr.datagram.mbx.coe.sdoinfo.entrydesc.bitlen',), 'value'),
    'ecat_mailbox.coe.sdoinfodatatype': (('ecatr.datagram.mbx.coe.sdoinfo.objdesc.datatype',), 'value'),
    'ecat_mailbox.coe.sdoinfoerrorcode': (('ecatr.datagram.mbx.coe.sdoinfo.errorcode',), 'value'),
    'ecat_mailbox.coe.sdoinfofrag': (('ecatr.datagram.mbx.coe.sdoinfo.fragsleft',), 'value'),
    'ecat_mailbox.coe.sdoinfoindex': (('ecatr.datagram.mbx.coe.sdoinfo.index',), 'value'),
    'ecat_mailbox.coe.sdoinfolisttype': (('ecatr.datagram.mbx.coe.sdoinfo.listtype',), 'value'),
    'ecat_mailbox.coe.sdoinfomaxsub': (('ecatr.datagram.mbx.coe.sdoinfo.objdesc.maxsub',), 'value'),
    'ecat_mailbox.coe.sdoinfoname': (('ecatr.datagram.mbx.coe.sdoinfo.objdesc.name',), 'value'),
    'ecat_mailbox.coe.sdoinfoobjaccess': (('ecatr.datagram.mbx.coe.sdoinfo.entrydesc.objaccess',), 'value'),
    'ecat_mailbox.coe.sdoinfoobjcode': (('ecatr.datagram.mbx.coe.sdoinfo.objdesc.objcode',), 'value'),
    'ecat_mailbox.coe.sdoinfoopcode': (('ecatr.datagram.mbx.coe.sdoinfo.opcode',), 'value'),
    'ecat_mailbox.coe.sdoinfosubindex': (('ecatr.datagram.mbx.coe.sdoinfo.entrydesc.subindex',), 'value'),
    'ecat_mailbox.coe.sdoinfovalueinfo': (('ecatr.datagram.mbx.coe.sdoinfo.entrydesc.valueinfo',), 'value'),
    'ecat_mailbox.coe.sdolength': (('ecatr.datagram.mbx.coe.sdoreq.normal.size', 'ecatr.datagram.mbx.coe.sdores.normal.size'), 'value'),
    'ecat_mailbox.coe.sdoreq': (('ecatr.datagram.mbx.coe.sdoreq.cmd.cs',), 'value'),
    'ecat_mailbox.coe.sdores': (('ecatr.datagram.mbx.coe.sdores.cmd.cs',), 'value'),
    'ecat_mailbox.coe.sdoscsds': (('ecatr.datagram.mbx.coe.sdores.dlseg',), 'container'),
    'ecat_mailbox.coe.sdoscsds_toggle': (('ecatr.datagram.mbx.coe.sdores.dlseg.toggle',), 'value'),
    'ecat_mailbox.coe.sdoscsiu': (('ecatr.datagram.mbx.coe.sdores.initul',), 'container'),
    'ecat_mailbox.coe.sdoscsiu_complete': (('ecatr.datagram.mbx.coe.sdores.initul.complete',), 'value'),
    'ecat_mailbox.coe.sdoscsiu_expedited': (('ecatr.datagram.mbx.coe.sdores.initul.expedited',), 'value'),
    'ecat_mailbox.coe.sdoscsiu_size0': (('ecatr.datagram.mbx.coe.sdores.initul.size',), 'bit0'),
    'ecat_mailbox.coe.sdoscsiu_size1': (('ecatr.datagram.mbx.coe.sdores.initul.size',), 'bit1'),
    'ecat_mailbox.coe.sdoscsiu_sizeind': (('ecatr.datagram.mbx.coe.sdores.initul.sizeind',), 'value'),
    'ecat_mailbox.coe.sdoscsus': (('ecatr.datagram.mbx.coe.sdores.ulseg',), 'container'),
    'ecat_mailbox.coe.sdoscsus_bytes': (('ecatr.datagram.mbx.coe.sdores.ulseg.size',), 'value'),
    'ecat_mailbox.coe.sdoscsus_lastseg': (('ecatr.datagram.mbx.coe.sdores.ulseg.lastseg',), 'value'),
    'ecat_mailbox.coe.sdoscsus_toggle': (('ecatr.datagram.mbx.coe.sdores.ulseg.toggle',), 'value'),
    'ecat_mailbox.coe.sdosub': (('ecatr.datagram.mbx.coe.sdoreq.subindex', 'ecatr.datagram.mbx.coe.sdores.subindex'), 'value'),
    'ecat_mailbox.coe.type': (('ecatr.datagram.mbx.coe.type',), 'value'),
    'ecat_mailbox.counter': (('ecatr.datagram.mbx.counter',), 'value'),
    'ecat_mailbox.eoe.fragment': (('ecatr.datagram.mbx.eoe.fragment',), 'value'),
    'ecat_mailbox.eoe.fragno': (('ecatr.datagram.mbx.eoe.fragno',), 'value'),
    'ecat_mailbox.eoe.frame': (('ecatr.datagram.mbx.eoe.frame',), 'value'),
    'ecat_mailbox.eoe.init.contains_defaultgateway': (('ecatr.datagram.mbx.eoe.init.contains_defaultgateway',), 'value'),
    'ecat_mailbox.eoe.init.contains_dnsname': (('ecatr.datagram.mbx.eoe.init.contains_dnsname',), 'value'),
    'ecat_mailbox.eoe.init.contains_dnsserver': (('ecatr.datagram.mbx.eoe.init.contains_dnsserver',), 'value'),
    'ecat_mailbox.eoe.init.contains_ipaddr': (('ecatr.datagram.mbx.eoe.init.contains_ipaddr',), 'value'),
    'ecat_mailbox.eoe.init.contains_macaddr': (('ecatr.datagram.mbx.eoe.init.contains_macaddr',), 'value'),
    'ecat_mailbox.eoe.init.contains_subnetmask': (('ecatr.datagram.mbx.eoe.init.contains_subnetmask',), 'value'),
    'ecat_mailbox.eoe.init.defaultgateway': (('ecatr.datagram.mbx.eoe.init.defaultgateway',), 'ipv4'),
    'ecat_mailbox.eoe.init.dnsname': (('ecatr.datagram.mbx.eoe.init.dnsname',), 'text'),
    'ecat_mailbox.eoe.init.dnsserver': (('ecatr.datagram.mbx.eoe.init.dnsserver',), 'ipv4'),
    'ecat_mailbox.eoe.init.ipaddr': (('ecatr.datagram.mbx.eoe.init.ipaddr',), 'ipv4'),
    'ecat_mailbox.eoe.init.macaddr': (('ecatr.datagram.mbx.eoe.init.macaddr',), 'value'),
    'ecat_mailbox.eoe.init.subnetmask': (('ecatr.datagram.mbx.eoe.init.subnetmask',), 'ipv4'),
    'ecat_mailbox.eoe.last': (('ecatr.datagram.mbx.eoe.last',), 'value'),
    'ecat_mailbox.eoe.macfilter.macfiltercount': (('ecatr.datagram.mbx.eoe.macfilter.macfiltercount',), 'value'),
    'ecat_mailbox.eoe.macfilter.maskcount': (('ecatr.datagram.mbx.eoe.macfilter.maskcount',), 'value'),
    'ecat_mailbox.eoe.macfilter.nobroadcasts': (('ecatr.datagram.mbx.eoe.macfilter.nobroadcasts',), 'value'),
    'ecat_mailbox.eoe.offset': (('ecatr.datagram.mbx.eoe.offset',), 'x32'),
    'ecat_mailbox.eoe.timestamp': (('ecatr.datagram.mbx.eoe.timestamp',), 'value'),
    'ecat_mailbox.eoe.timestampapp': (('ecatr.datagram.mbx.eoe.timestampapp',), 'value'),
    'ecat_mailbox.eoe.timestampreq': (('ecatr.datagram.mbx.eoe.timestampreq',), 'value'),
    'ecat_mailbox.eoe.type': (('ecatr.datagram.mbx.eoe.type',), 'value'),
    'ecat_mailbox.foe_busydata': (('ecatr.datagram.mbx.foe.data',), 'value'),
    'ecat_mailbox.foe_busydone': (('ecatr.datagram.mbx.foe.busydone',), 'value'),
    'ecat_mailbox.foe_busyentire': (('ecatr.datagram.mbx.foe.busyentire',), 'value'),
    'ecat_mailbox.foe_errcode': (('ecatr.datagram.mbx.foe.errcode',), 'value'),
    'ecat_mailbox.foe_errtext': (('ecatr.datagram.mbx.foe.errtext',), 'value'),
    'ecat_mailbox.foe_filelength': (('ecatr.datagram.mbx.foe.password',), 'value'),
    'ecat_mailbox.foe_filename': (('ecatr.datagram.mbx.foe.filename',), 'value'),
    'ecat_mailbox.foe_opmode': (('ecatr.datagram.mbx.foe.opmode',), 'value'),
    'ecat_mailbox.foe_packetno': (('ecatr.datagram.mbx.foe.packetno',), 'value'),
    'ecat_mailbox.length': (('ecatr.datagram.mbx.length',), 'value'),
    'ecat_mailbox.priority': (('ecatr.datagram.mbx.priority',), 'value'),
    'ecat_mailbox.soe_data': (('ecatr.datagram.mbx.soe.data',), 'value'),
    'ecat_mailbox.soe_error': (('ecatr.datagram.mbx.soe.errorcode',), 'value'),
    'ecat_mailbox.soe_frag': (('ecatr.datagram.mbx.soe.frag',), 'value'),
    'ecat_mailbox.soe_header': (('ecatr.datagram.mbx.soe.header',), 'container'),
    'ecat_mailbox.soe_header_attribute': (('ecatr.datagram.mbx.soe.header.attribute',), 'value'),
    'ecat_mailbox.soe_header_datastate': (('ecatr.datagram.mbx.soe.header.datastate',), 'value'),
    'ecat_mailbox.soe_header_driveno': (('ecatr.datagram.mbx.soe.header.driveno',), 'value'),
    'ecat_mailbox.soe_header_error': (('ecatr.datagram.mbx.soe.header.error',), 'value'),
    'ecat_mailbox.soe_header_incomplete': (('ecatr.datagram.mbx.soe.header.incomplete',), 'value'),
    'ecat_mailbox.soe_header_max': (('ecatr.datagram.mbx.soe.header.max',), 'value'),
    'ecat_mailbox.soe_header_min': (('ecatr.datagram.mbx.soe.header.min',), 'value'),
    'ecat_mailbox.soe_header_name': (('ecatr.datagram.mbx.soe.header.name',), 'value'),
    'ecat_mailbox.soe_header_reserved': (('ecatr.datagram.mbx.soe.header.reserved',), 'value'),
    'ecat_mailbox.soe_header_unit': (('ecatr.datagram.mbx.soe.header.unit',), 'value'),
    'ecat_mailbox.soe_header_value': (('ecatr.datagram.mbx.soe.header.value',), 'value'),
    'ecat_mailbox.soe_idn': (('ecatr.datagram.mbx.soe.idn',), 'value'),
    'ecat_mailbox.soe_opcode': (('ecatr.datagram.mbx.soe.header.opcode',), 'value'),
    'ecat_mailbox.type': (('ecatr.datagram.mbx.type',), 'value'),
}

# Where Wireshark's value is wrong, by the ESC datasheet (section II) or ETG.1000; ours shows
# the datasheet's layout.  field -> (reason, predicate(ws value, ours values) that recognises
# exactly the wrong case).
def _only_bit4_differs(w, o):
    return isinstance(w, int) and any(isinstance(v, int) and (v & 0x0F) == w and v != w for v in o)


KNOWN_WRONG = {
    "ecat.reg.mio.ctrlstat.offsphy": (
        "ws-mii-offset-mask: Wireshark masks the PHY address offset with 0x008f (bits 0-3 and 7); "
        "the ESC datasheet has it in bits 3-7 (0x00f8)", lambda w, o: True),
    "ecat.reg.mio.addr.phyaddr": (
        "ws-mii-address-width: Wireshark shows 4 bits of the PHY address, the datasheet 5 (bits 0-4)",
        _only_bit4_differs),
    "ecat.reg.mio.addr.mioaddr": (
        "ws-mii-address-width: Wireshark shows 4 bits of the PHY register address, the datasheet 5 (bits 8-12)",
        _only_bit4_differs),
    "ecat_mailbox.soe_error": (
        "ws-soe-error-offset: with the error flag set Wireshark reads the SoE error code at the IDN's bytes; "
        "ETG.1000.6 puts it after the IDN (ours)", None),
    "ecat_mailbox.soe_idn": (
        "ws-soe-incomplete: with the incomplete and error flags set Wireshark still shows an IDN where "
        "ETG.1000.6 has the fragments left (ours)", None),
    "ecat_mailbox.priority": (
        "ws-mailbox-priority: Wireshark shows bits 0-1 of the mailbox header's byte 4 as the priority; "
        "ETG.1000.4 has the channel in bits 0-5 and the priority in bits 6-7",
        lambda w, o: True),
}

# The datagram's own fields (compared by ecat_differential.py).
DATAGRAM_FIELDS = {"ecat.cmd", "ecat.idx", "ecat.adp", "ecat.ado", "ecat.lad", "ecat.int", "ecat.cnt", "ecat.data"}

NUMERIC_TYPES = {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14}  # ftenum_t of FT_BOOLEAN..FT_INT64


class DeepStats:
    def __init__(self):
        self.compared = 0
        self.agree = 0
        self.explained = defaultdict(int)
        self.mismatch = defaultdict(int)
        self.unmapped = defaultdict(int)      # Wireshark fields we do not compare (listed)
        self.per_field = defaultdict(lambda: [0, 0])   # ws field -> [compared, agreed]
        self.examples = []

    def report(self):
        lines = ["Registers and mailboxes (Wireshark's values inside the data, matched by field and position):",
                 "  %d values compared: %d agree, %d explained (Wireshark wrong), %d mismatch" %
                 (self.compared, self.agree, sum(self.explained.values()), sum(self.mismatch.values())),
                 "  Wireshark fields seen: %d; our fields they matched: see the per-field table with --keep" %
                 len(self.per_field)]
        for k in sorted(self.explained):
            lines.append("  explained %6d x %s" % (self.explained[k], k))
        for k in sorted(self.mismatch, key=lambda k: -self.mismatch[k]):
            lines.append("  MISMATCH  %6d x %s" % (self.mismatch[k], k))
        if self.unmapped:
            lines.append("  not compared (no counterpart by design): " +
                         ", ".join("%s %d" % (k, v) for k, v in sorted(self.unmapped.items())))
        for e in self.examples[:10]:
            lines.append("  e.g. " + e)
        return "\n".join(lines)


class _Obj(list):
    pass


def items_per_packet(path, prefixes):
    """tshark -T json -x -> [ {(name, pos): [(length, show)]} ] per packet, for fields whose name
    starts with one of prefixes."""
    pkts = json.loads(read_tshark_output(path), object_pairs_hook=_Obj)
    out = []
    for pk in pkts:
        found = defaultdict(list)

        def walk(obj):
            shows = defaultdict(list)
            raws = defaultdict(list)
            for k, v in obj:
                if isinstance(v, _Obj):
                    walk(v)
                    continue
                if k.endswith("_raw"):
                    base = k[:-4]
                    if base.startswith(prefixes) and isinstance(v, list) and len(v) == 5 and \
                            not isinstance(v[0], list):
                        raws[base].append(v)
                elif k.startswith(prefixes) and isinstance(v, str):
                    shows[k].append(v)
                elif k.startswith(prefixes) and isinstance(v, list):   # repeated key merged by tshark
                    shows[k].extend(x for x in v if isinstance(x, str))
            for name, rl in raws.items():
                sl = shows.get(name, [])
                for i, r in enumerate(rl):
                    found[(name, r[1])].append((r[2], sl[i] if i < len(sl) else "", r[4], r[3]))

        walk(pk)
        out.append(found)
    return out


_INT = re.compile(r"-?(0[xX][0-9a-fA-F]+|[0-9]+)")
_SECS = re.compile(r"(-?[0-9]+\.[0-9]+)( seconds)?")


def normal(show, ftype):
    s = show.strip()
    if s in ("True", "False"):
        return int(s == "True")
    if _INT.fullmatch(s) and ftype in NUMERIC_TYPES:
        return int(s, 0) if not s.startswith("-") else -int(s[1:], 0)
    m = _SECS.fullmatch(s)
    if m:       # a time shown in seconds: compare the count of nanoseconds
        try:
            return int(Decimal(m.group(1)) * 1000000000)
        except InvalidOperation:
            pass
    if re.fullmatch(r"([0-9a-fA-F]{2}[: ]?)+", s) and ftype not in NUMERIC_TYPES:
        return s.replace(":", "").replace(" ", "").lower()
    return s


def same(w, o, length, kind):
    if kind == "x32":           # Wireshark shows the EoE offset in bytes, ours in 32-byte units
        return isinstance(o, int) and isinstance(w, int) and o * 32 == w
    if kind == "ipv4":          # an IPv4 address stored little-endian: dotted, or its bytes
        if isinstance(o, str) and re.fullmatch(r"[0-9a-f]{8}", o):
            o = ".".join(str(b) for b in reversed(bytes.fromhex(o)))
        return o == w
    if kind == "text":          # a NUL-padded name: text, or its bytes
        if isinstance(o, str) and re.fullmatch(r"([0-9a-f]{2})+", o):
            o = bytes.fromhex(o).split(b"\0")[0].decode("utf-8", "replace")
        return o == w
    if kind.startswith("bit"):
        n = int(kind[3:])
        return isinstance(o, int) and isinstance(w, int) and ((o >> n) & 1) == w
    if isinstance(w, int) and isinstance(o, int):
        mod = 1 << (8 * max(length, 1))
        return (w - o) % mod == 0
    return w == o


def compare_packet(num, ws_items, ours_items, stats, stops=()):
    """Returns the list of unexplained differences (strings) of one packet.  stops: (frame
    position, end or None, why) where ours shows nothing by design (inside a malformed mailbox,
    which it skips; from where Wireshark decodes past the header's Length on)."""
    problems = []
    for (wname, pos), wl in ws_items.items():
        if wname in DATAGRAM_FIELDS or wname.startswith(("ecat.sub", "ecat.subframe.")):
            continue        # compared by ecat_differential.py itself
        m = DEEP_MAP.get(wname)
        if m is None:
            stats.unmapped[wname] += len(wl)
            continue
        names, kind = m
        for (length, show, ftype, mask) in wl:
            stats.compared += 1
            pf = stats.per_field[wname]
            pf[0] += 1
            # Ours may place a bit field on the bytes that hold its bits only (the second byte
            # of a 16-bit register), Wireshark on the whole register: any start inside counts.
            cands = []
            for n in names:
                for p in range(pos, pos + max(length, 1)):
                    cands += [(ol, normal(os_, ot)) for (ol, os_, ot, om) in ours_items.get((n, p), [])
                              if p == pos or p + ol <= pos + length]
            if kind == "container":
                ok = bool(cands)
            else:
                w = normal(show, ftype)
                ok = any(same(w, o, length, kind) for _, o in cands)
            if ok:
                stats.agree += 1
                pf[1] += 1
                continue
            # (an item that reaches past the stop is not shown either: ours shows only whole registers)
            why = next((w for at, until, w in stops if pos + max(length, 1) > at and (until is None or pos < until)),
                       None) if not cands else None
            if why:
                stats.explained[why.split(":")[0]] += 1
                continue
            known = KNOWN_WRONG.get(wname)
            # predicate None: Wireshark's field is at bytes that mean something else (ours has
            # another field there)
            if known and (known[1] is None or (cands and known[1](normal(show, ftype), [o for _, o in cands]))):
                stats.explained[known[0].split(":")[0]] += 1
                continue
            what = "%s at %d: Wireshark %r, ours %s" % (
                wname, pos, show, ", ".join("%r" % (o,) for _, o in cands) or "nothing at these bytes (%s)" %
                " / ".join(names))
            stats.mismatch[wname] += 1
            if len(stats.examples) < 40:
                stats.examples.append("frame %d: %s" % (num, what))
            problems.append(what)
    return problems
