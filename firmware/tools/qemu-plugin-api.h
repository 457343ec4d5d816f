/*
 * qemu-plugin-api.h: the part of QEMU's TCG plugin API that the firmware's
 * plugins (qemu-count.c, qemu-cores.c, qemu-profile.c) call, declared here
 * because Debian's qemu-system-arm and qemu-system-misc load plugins but no
 * Debian package ships QEMU's header for them.
 *
 * The declarations are those of plugin API version 1, QEMU 7.2's (Debian
 * 12), checked against that release's include/qemu/qemu-plugin.h: the
 * functions' signatures, the two enumerators' values and the version
 * constant. The plugin ABI is plain C: a plugin exports qemu_plugin_version
 * and qemu_plugin_install, and calls the qemu_plugin_* functions the QEMU
 * executable exports. QEMU refuses to load a plugin whose version lies
 * outside the range it supports, so a QEMU whose API has moved on says so
 * rather than running a plugin against declarations that no longer hold.
 *
 * Only what the plugins use is declared; qemu_info_t stays incomplete, as
 * none of them reads it.
 */
#ifndef OCTRACE_QEMU_PLUGIN_API_H
#define OCTRACE_QEMU_PLUGIN_API_H

#include <stddef.h>
#include <stdint.h>

/* The API version the plugins are written against. */
#define QEMU_PLUGIN_VERSION 1

/* The two symbols QEMU looks up; build with -fvisibility=hidden so that
   they are the only ones exported. */
#define QEMU_PLUGIN_EXPORT __attribute__((visibility("default")))

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;   /* a translated block, valid during its callback */
struct qemu_plugin_insn; /* one instruction of such a block */

/* Whether a callback reads or writes the guest's registers: ours do not. */
enum qemu_plugin_cb_flags {
    QEMU_PLUGIN_CB_NO_REGS = 0,
};

/* The operations QEMU can inline into translated code. */
enum qemu_plugin_op {
    QEMU_PLUGIN_INLINE_ADD_U64 = 0,
};

typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);

/* Defined by each plugin. */
extern QEMU_PLUGIN_EXPORT int qemu_plugin_version;
QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv);

/* Called at every translation, and once when QEMU exits. */
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);

/* A translated block and its instructions. */
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
uint64_t qemu_plugin_tb_vaddr(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);

/* What runs each time a block or an instruction executes. */
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, qemu_plugin_vcpu_udata_cb_t cb,
                                          enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn, enum qemu_plugin_op op,
                                                void *ptr, uint64_t imm);

#endif
