/* The one place that knows how Wireshark's plugin API differs between the
 * versions dissgen supports; generated code and the runtime include only
 * this. */
#pragma once

#include <ws_version.h>
#include <epan/packet.h>
#include <epan/expert.h>
#include <epan/proto.h>
#include <epan/dissectors/packet-tcp.h>
#include <wsutil/report_message.h>

#if WIRESHARK_VERSION_MAJOR > 4 || (WIRESHARK_VERSION_MAJOR == 4 && WIRESHARK_VERSION_MINOR >= 4)
#define DG_HAVE_PLUGIN_DESCRIBE 1
#include <wsutil/plugins.h>
#endif

/* The plugin loader's entry points. In C++ a namespace-scope const has
 * internal linkage, so the data symbols are declared extern (inside an
 * extern "C" block) before they are defined.
 *
 * The protocol is registered at the start of the handoff phase, not in the
 * register phase: per-user plugins register before global ones, so only
 * after every plugin's register routine has run can a protocol whose names
 * are taken (say, by Debian's ethercat.so) step aside instead of making
 * Wireshark abort on a duplicate name. Subtree and field arrays are still
 * open for registration then. */
#ifdef __cplusplus
#define DG_BEGIN_C extern "C" {
#define DG_END_C }
#else
#define DG_BEGIN_C
#define DG_END_C
#endif

#define DG_DECLARE_PLUGIN(register_fn, handoff_fn)                                   \
    static void dg_register_nothing_yet(void) {}                                     \
    static void dg_register_then_handoff(void)                                       \
    {                                                                                \
        register_fn();                                                               \
        handoff_fn();                                                                \
    }                                                                                \
    DG_BEGIN_C                                                                       \
    WS_DLL_PUBLIC_DEF extern const char plugin_version[];                            \
    WS_DLL_PUBLIC_DEF extern const int plugin_want_major;                            \
    WS_DLL_PUBLIC_DEF extern const int plugin_want_minor;                            \
    WS_DLL_PUBLIC void plugin_register(void);                                        \
    const char plugin_version[] = "1.0";                                             \
    const int plugin_want_major = WIRESHARK_VERSION_MAJOR;                           \
    const int plugin_want_minor = WIRESHARK_VERSION_MINOR;                           \
    void plugin_register(void)                                                       \
    {                                                                                \
        static proto_plugin plug;                                                    \
        plug.register_protoinfo = dg_register_nothing_yet;                           \
        plug.register_handoff = dg_register_then_handoff;                            \
        proto_register_plugin(&plug);                                                \
    }                                                                                \
    DG_END_C
