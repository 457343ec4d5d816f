/*
 * qemu-profile.c - a QEMU TCG plugin (API v1) that counts how many times each
 * guest instruction in flash executes, and writes "address count" lines for
 * the non-zero ones to the file named by out=PATH at exit. profile.sh maps
 * them to functions. Exact and repeatable, like qemu-count: these are
 * instructions executed, not cycles.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "qemu-plugin-api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

#define FLASH_BYTES (4u << 20) /* covers both boards' flash at 0x0 */
static uint64_t *counts;       /* one per halfword address */
static const char *out_path = "profile.txt";

static void tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t va = qemu_plugin_insn_vaddr(insn);
        if (va < FLASH_BYTES) {
            qemu_plugin_register_vcpu_insn_exec_inline(
                insn, QEMU_PLUGIN_INLINE_ADD_U64, &counts[va / 2], 1);
        }
    }
}

static void at_exit(qemu_plugin_id_t id, void *p)
{
    FILE *f = fopen(out_path, "w");
    if (!f) {
        return;
    }
    for (uint64_t i = 0; i < FLASH_BYTES / 2; i++) {
        if (counts[i]) {
            fprintf(f, "%" PRIx64 " %" PRIu64 "\n", i * 2, counts[i]);
        }
    }
    fclose(f);
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id,
                                           const qemu_info_t *info,
                                           int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "out=", 4) == 0) {
            out_path = argv[i] + 4;
        } else {
            fprintf(stderr, "qemu-profile: bad option %s\n", argv[i]);
            return -1;
        }
    }
    counts = calloc(FLASH_BYTES / 2, sizeof *counts);
    if (!counts) {
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, tb_trans);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
