/*
 * qemu-cores.c - a QEMU TCG plugin (API v1) that counts the instructions
 * each vCPU (core) executes between the first two executions of the
 * instruction at marker=ADDR, and of those how many in wait=START-END (a
 * core spinning for the other). At exit it writes "core N insns T wait W"
 * lines to out=PATH. Counted per translation block, exact and repeatable;
 * instructions, not cycles.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "qemu-plugin-api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

#define MAX_CORES 8
static uint64_t insns[MAX_CORES], waits[MAX_CORES];
static uint64_t marked_insns[2][MAX_CORES], marked_waits[2][MAX_CORES];
static int marks;
static uint64_t marker = UINT64_MAX, wait_start = 1, wait_end = 0;
static const char *out_path = "cores.txt";

/* udata: the block's instruction count, with bit 62 set for a block in the
   wait range and bit 63 for the marker's block. */
#define IN_WAIT (1ull << 62)
#define AT_MARKER (1ull << 63)

static void tb_exec(unsigned int vcpu, void *udata)
{
    uint64_t info = (uint64_t)(uintptr_t)udata;
    if (vcpu >= MAX_CORES) {
        return;
    }
    if ((info & AT_MARKER) && marks < 2) {
        memcpy(marked_insns[marks], insns, sizeof insns);
        memcpy(marked_waits[marks], waits, sizeof waits);
        marks++;
    }
    uint64_t n = info & ~(IN_WAIT | AT_MARKER);
    insns[vcpu] += n;
    if (info & IN_WAIT) {
        waits[vcpu] += n;
    }
}

static void tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    uint64_t va = qemu_plugin_tb_vaddr(tb) & ~1ull;
    uint64_t info = qemu_plugin_tb_n_insns(tb);
    if (va >= wait_start && va < wait_end) {
        info |= IN_WAIT;
    }
    if (va == marker) {
        info |= AT_MARKER;
    }
    qemu_plugin_register_vcpu_tb_exec_cb(tb, tb_exec, QEMU_PLUGIN_CB_NO_REGS, (void *)(uintptr_t)info);
}

static void at_exit(qemu_plugin_id_t id, void *p)
{
    FILE *f = fopen(out_path, "w");
    if (!f) {
        return;
    }
    int end = marks == 2 ? 1 : -1;
    for (int c = 0; c < MAX_CORES; c++) {
        uint64_t t = end > 0 ? marked_insns[1][c] - marked_insns[0][c] : insns[c];
        uint64_t w = end > 0 ? marked_waits[1][c] - marked_waits[0][c] : waits[c];
        if (insns[c]) {
            fprintf(f, "core %d insns %" PRIu64 " wait %" PRIu64 "%s\n", c, t, w, end > 0 ? "" : " (no markers)");
        }
    }
    fclose(f);
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "out=", 4) == 0) {
            out_path = argv[i] + 4;
        } else if (strncmp(argv[i], "marker=", 7) == 0) {
            marker = strtoull(argv[i] + 7, NULL, 0) & ~1ull;
        } else if (strncmp(argv[i], "wait=", 5) == 0) {
            char *dash;
            wait_start = strtoull(argv[i] + 5, &dash, 0) & ~1ull;
            wait_end = *dash == '-' ? strtoull(dash + 1, NULL, 0) : 0;
        } else {
            fprintf(stderr, "qemu-cores: bad option %s\n", argv[i]);
            return -1;
        }
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, tb_trans);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
