// SPDX-License-Identifier: GPL-2.0-or-later
/* The one place that knows how Wireshark's plugin API differs between the
 * versions dissgen supports; generated code and the runtime include only
 * this. */
#pragma once

#include <ws_version.h>
#include <epan/packet.h>
#include <epan/expert.h>
#include <epan/proto.h>
/* Reassembly and hand-off. reassemble.h and show_exception.h have no C++ guards;
 * packet-tcp.h includes reassemble.h outside its own, so they come first. */
#include <epan/exceptions.h>
extern "C" {
#include <epan/show_exception.h>
#include <epan/reassemble.h>
}
#include <epan/dissectors/packet-tcp.h>
#include <wsutil/report_message.h>
/* unit_name_string (unit="..." labels): packet.h includes it up to 4.2 only. */
#include <epan/unit_strings.h>

#include <epan/prefs.h>
#include <epan/stat_tap_ui.h>

#include <tuple>
#include <type_traits>
#include <utility>

/* True when the headers compiled against are Wireshark MAJOR.MINOR or later.
 * ws_version.h belongs to the headers, so a plugin's plugin_want_major/minor
 * (below) are those of the libwireshark-dev it was built with. */
#define DG_WS_AT_LEAST(major, minor)                                                  \
    (WIRESHARK_VERSION_MAJOR > (major) ||                                            \
     (WIRESHARK_VERSION_MAJOR == (major) && WIRESHARK_VERSION_MINOR >= (minor)))

/* format_text() takes its bytes as const guchar * in 4.0 and as const char *
 * in later versions: the pointer's type is deduced from the declaration. */
#include <epan/strutil.h>
template <typename Char>
static inline char *dg_format_text_with(char *(*format)(wmem_allocator_t *, const Char *, size_t),
                                        wmem_allocator_t *scope, const guint8 *text, size_t length)
{
    return format(scope, reinterpret_cast<const Char *>(text), length);
}
/* Text for display: non-printable characters escaped, as Wireshark shows strings. */
static inline char *dg_format_text(wmem_allocator_t *scope, const guint8 *text, size_t length)
{
    return dg_format_text_with(format_text, scope, text, length);
}

/* 4.4 installs wsutil/plugins.h (absent in 4.0) with the plugin description
 * flags; its loader calls an optional plugin_describe(). */
#if DG_WS_AT_LEAST(4, 4)
#include <wsutil/plugins.h>
#endif
#ifdef WS_PLUGIN_DESC_DISSECTOR
#define DG_HAVE_PLUGIN_DESCRIBE 1
#endif

/* Integer reads. 4.4 renamed tvb_get_guintN to tvb_get_uintN and deprecated
 * the old names (an error with -Werror); 4.0 has only the old ones. */
#if DG_WS_AT_LEAST(4, 4)
#define dg_tvb_get_uint8 tvb_get_uint8
#define dg_tvb_get_uint16 tvb_get_uint16
#define dg_tvb_get_uint24 tvb_get_uint24
#define dg_tvb_get_uint32 tvb_get_uint32
#define dg_tvb_get_uint40 tvb_get_uint40
#define dg_tvb_get_uint48 tvb_get_uint48
#define dg_tvb_get_uint56 tvb_get_uint56
#define dg_tvb_get_uint64 tvb_get_uint64
#else
#define dg_tvb_get_uint8 tvb_get_guint8
#define dg_tvb_get_uint16 tvb_get_guint16
#define dg_tvb_get_uint24 tvb_get_guint24
#define dg_tvb_get_uint32 tvb_get_guint32
#define dg_tvb_get_uint40 tvb_get_guint40
#define dg_tvb_get_uint48 tvb_get_guint48
#define dg_tvb_get_uint56 tvb_get_guint56
#define dg_tvb_get_uint64 tvb_get_guint64
#endif

/* What a heuristic dissector returns: gboolean up to 4.2, bool from 4.4 on. */
typedef decltype(std::declval<heur_dissector_t>()(nullptr, nullptr, nullptr, nullptr)) dg_heur_result;

/* The variable of a bool preference: gboolean up to 4.2, bool from 4.4 on
 * (the type prefs_register_bool_preference() points its last argument at). */
template <typename R, typename... A> std::tuple_element_t<sizeof...(A) - 1, std::tuple<A...>> dg_last_argument(R (*)(A...));
typedef std::remove_pointer_t<decltype(dg_last_argument(&prefs_register_bool_preference))> dg_pref_bool;

/* What a command-line statistic's init callback (stat_tap_ui.init) returns:
 * nothing up to 4.4, whether it worked from 4.6 on. dg_tap_init_done(ok)
 * returns that. */
typedef decltype(std::declval<stat_tap_init_cb>()(nullptr, nullptr)) dg_tap_init_result;
template <typename R = dg_tap_init_result> R dg_tap_init_done(bool ok)
{
    if constexpr (std::is_void_v<R>) {
        (void)ok;
        return;
    } else {
        return ok;
    }
}

/* 4.4 renamed tvb_find_guint8 too (stringz leaves look for their NUL). */
#if DG_WS_AT_LEAST(4, 4)
#define dg_tvb_find_uint8 tvb_find_uint8
#else
#define dg_tvb_find_uint8 tvb_find_guint8
#endif

/* The text of an item without one set (the window instance
 * labels). 4.6 (4.5 development) added an out-parameter for where the value
 * starts; 4.0 and 4.4 have two parameters. */
#if DG_WS_AT_LEAST(4, 5)
#define dg_fill_label(finfo, label) proto_item_fill_label((finfo), (label), NULL)
#else
#define dg_fill_label(finfo, label) proto_item_fill_label((finfo), (label))
#endif

/* Differences that need no code here, checked against 4.0, 4.4 and 4.6
 * (tests/multiversion/compile_all.sh):
 * - EI_INIT is {-1,-1} before 4.6 and {0,0} from 4.6: generated code leaves
 *   its expert_field ids zero-initialised (static storage), which every
 *   version's expert_register_field_array() accepts, and uses them only
 *   after registering them.
 * - ett_ ids must start at -1 before 4.4 (0 is also accepted later):
 *   generated code initialises them to -1.
 * - value_string.h moved from epan/ to wsutil/ in 4.6: only epan/packet.h is
 *   included, which includes it from wherever it lives.
 * - gboolean/guint/gint parameters became bool/unsigned/int in 4.4 (the glib
 *   types are not deprecated): guint and unsigned are the same type, so
 *   callbacks (tcp_dissect_pdus' length function) match both, and TRUE
 *   converts to bool.
 * - proto_name_already_registered() returns int in 4.0, bool later: only
 *   tested for truth. */

/* The plugin loader's entry points, with C linkage: the loader looks them up
 * by their plain names. In C++ a namespace-scope const has internal linkage,
 * so the data symbols are declared extern (inside the extern "C" block)
 * before they are defined.
 *
 * The protocol is registered at the start of the handoff phase, not in the
 * register phase: per-user plugins register before global ones, so only
 * after every plugin's register routine has run can a protocol whose names
 * are taken (say, by Debian's ethercat.so) step aside instead of making
 * Wireshark abort on a duplicate name. Subtree and field arrays are still
 * open for registration then. */
/* 4.4+: tell the loader this plugin is a dissector (shown by tshark -G plugins
 * and Wireshark's About dialog). */
#ifdef DG_HAVE_PLUGIN_DESCRIBE
#define DG_DEFINE_PLUGIN_DESCRIBE                                                    \
    WS_DLL_PUBLIC uint32_t plugin_describe(void);                                    \
    uint32_t plugin_describe(void) { return WS_PLUGIN_DESC_DISSECTOR; }
#else
#define DG_DEFINE_PLUGIN_DESCRIBE
#endif

#define DG_DECLARE_PLUGIN(register_fn, handoff_fn)                                   \
    static void dg_register_nothing_yet(void) {}                                     \
    static void dg_register_then_handoff(void)                                       \
    {                                                                                \
        register_fn();                                                               \
        handoff_fn();                                                                \
    }                                                                                \
    extern "C" {                                                                     \
    WS_DLL_PUBLIC_DEF extern const char plugin_version[];                            \
    WS_DLL_PUBLIC_DEF extern const int plugin_want_major;                            \
    WS_DLL_PUBLIC_DEF extern const int plugin_want_minor;                            \
    WS_DLL_PUBLIC void plugin_register(void);                                        \
    DG_DEFINE_PLUGIN_DESCRIBE                                                        \
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
    }
