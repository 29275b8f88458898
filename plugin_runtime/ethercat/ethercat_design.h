/* The EtherCAT bus as dissgen knows it at build time: the device catalogue of
 * the ESI files given to `dissgen install --esi`, and the designed network of
 * `--network` (a design or an ENI file). The generator writes these tables
 * into the plugin as constant data (see generator/ethercat/emit_catalogue.cpp); the
 * run-time slave model reads them. Plain C data, no constructors. */
#ifndef DISSGEN_ETHERCAT_DESIGN_H
#define DISSGEN_ETHERCAT_DESIGN_H

#include <glib.h>

/* One PDO entry, placed in its slave's inputs or outputs. */
typedef struct dg_pdo_entry {
    guint16 index;           /* object index; 0 for padding */
    guint8 subindex;
    guint8 output;           /* 1: RxPdo (master to slave), 0: TxPdo (inputs) */
    guint16 bit_length;
    guint16 pdo_index;       /* the PDO (0x1600.., 0x1A00..) it belongs to */
    guint32 bit_offset;      /* from the start of the slave's inputs or outputs */
    gint64 logical_bit;      /* in the logical process image (ENI), -1: set by the master at run time */
    const char *name;        /* "Channel 1.Input": PDO name and entry name */
    const char *data_type;   /* ESI data type: "BOOL", "UINT", "BIT2", ... */
    int *hf;                 /* registered field, NULL when none (padding; with a network, models it does not use) */
} dg_pdo_entry;

/* A SyncManager of a slave of the network (ESI <Sm> defaults, or the ENI's <SmN>). */
typedef struct dg_sync_manager {
    guint8 index;            /* SM number */
    guint8 control;          /* control byte (direction, mode) */
    guint16 start;           /* physical start address */
    guint16 size;            /* default length, 0 when not given */
    guint8 enable;
    const char *type;        /* "Outputs", "Inputs", "MBoxOut", "MBoxIn" */
} dg_sync_manager;

/* One entry of a PDO's mapping as the ESI file gives it: no name, no
 * pointer (the catalogue holds thousands); the name and type are those of
 * the device's entry of that object (dg_device: default entries, then
 * objects). */
typedef struct dg_map_entry {
    guint16 index;           /* object index; 0 for padding */
    guint16 bit_length;
    guint8 subindex;
} dg_map_entry;

/* One PDO of a device, default or not: its mapping is maps[map_first ..]. */
typedef struct dg_pdo {
    guint16 index;           /* 0x1600.. (RxPdo), 0x1A00.. (TxPdo) */
    guint8 output;           /* 1: RxPdo */
    guint8 assigned;         /* 1: in the default assignment (the ESI gives it a SyncManager) */
    guint32 map_first, map_count;
} dg_pdo;

/* One device revision of the catalogue; its default process data (the PDOs
 * its ESI file assigns to a SyncManager) is entries[entry_first ..]. For a
 * master that assigns or maps other PDOs over CoE (0x1C12/0x1C13,
 * 0x16xx/0x1Axx): all its PDOs are pdos[pdo_first ..] (the default ones
 * first, in the order their process data is packed, then the others in
 * file order), and
 * entries[object_first ..] the objects only PDOs outside the default
 * assignment map (no field). Revisions that map alike share these ranges. */
typedef struct dg_device {
    guint32 vendor, product, revision;
    const char *type;        /* "EL1004" */
    const char *name;        /* English name */
    guint32 entry_first, entry_count;
    guint32 pdo_first, pdo_count;
    guint32 object_first, object_count;
} dg_device;

/* One slave of the designed network, by bus position. */
typedef struct dg_slave {
    guint16 position;        /* 0-based */
    guint16 station;         /* configured station address, 0 when the design gives none */
    guint32 vendor, product, revision;
    guint8 revision_given;   /* compare the revision too */
    gint32 device;           /* into dg_bus.devices, -1 when the model is not in the catalogue */
    const char *name;        /* instance name (ENI) or model name */
    guint32 entry_first, entry_count;  /* its process data */
    guint32 sm_first, sm_count;        /* its SyncManagers */
    guint32 input_bits, output_bits;
    gint64 input_logical_bit, output_logical_bit;  /* -1: not known before run time */
} dg_slave;

/* A datagram of the cyclic frames (ENI) with its expected working counter. */
typedef struct dg_cyclic_cmd {
    guint16 frame;           /* 0-based frame of the cycle */
    guint8 cmd;              /* EtherCAT command (10 LRD, 11 LWR, 12 LRW, ...) */
    guint16 adp, ado;        /* non-logical commands */
    guint32 logical_address; /* LRD/LWR/LRW */
    guint16 length;
    gint32 expected_wkc;     /* -1 when not given */
} dg_cyclic_cmd;

typedef struct dg_bus {
    const dg_device *devices;        /* sorted by vendor, product, revision */
    guint32 device_count;
    const dg_pdo_entry *entries;
    guint32 entry_count;
    const dg_pdo *pdos;              /* the devices' PDOs, see dg_device */
    guint32 pdo_count;
    const dg_map_entry *maps;        /* their mappings */
    guint32 map_count;
    const dg_slave *slaves;          /* NULL when no network was given */
    guint32 slave_count;
    const dg_sync_manager *sync_managers;
    guint32 sync_manager_count;
    const dg_cyclic_cmd *cyclic;
    guint32 cyclic_count;
} dg_bus;

#endif
