/*
 * qemu-count.c: a QEMU TCG plugin counting the guest instructions a
 * firmware executes, for the `qemu-count` script beside it (which builds it
 * and reads its report).
 *
 *     -plugin libqemu-count.so,out=PATH[,marker=ADDRESS]
 *
 * When QEMU exits, PATH receives `insns_total=N`, every instruction executed
 * from reset, and, if the instruction at ADDRESS (the firmware's
 * `bench_marker`; a Thumb symbol's low bit is dropped) ran at least twice,
 * `insns_between_markers=M`, the instructions between its first two runs.
 *
 * Every instruction adds one to the count in code QEMU inlines before it, so
 * the count is exact and repeatable on one vCPU: it does not depend on how
 * QEMU cuts the code into blocks, nor on an exception that leaves a block
 * early. The marker's callback reads the count when the marker is about to
 * run; whether QEMU places it before or after that instruction's own add
 * (7.2 runs callbacks first), both runs are read the same way, so their
 * difference is the same. Several vCPUs (the MPS2-AN521's two cores) share
 * the count without atomics: a close count there, not an exact one.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu-plugin-api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

static uint64_t executed;
static const char *report_path;
static int has_marker;
static uint64_t marker;
/* The count at the marker's first two runs, and how often it ran. */
static uint64_t at_marker[2];
static uint64_t marker_runs;

static void marker_ran(unsigned int vcpu_index, void *userdata)
{
    if (marker_runs < 2) {
        at_marker[marker_runs] = executed;
    }
    marker_runs++;
}

static void translated(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t count = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < count; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
        if (has_marker && qemu_plugin_insn_vaddr(insn) == marker) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, marker_ran, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
    }
}

static void write_report(qemu_plugin_id_t id, void *userdata)
{
    FILE *report = fopen(report_path, "w");
    if (report == NULL) {
        fprintf(stderr, "qemu-count: cannot write its report to %s\n", report_path);
        return;
    }
    fprintf(report, "insns_total=%" PRIu64 "\n", executed);
    if (marker_runs >= 2) {
        fprintf(report, "insns_between_markers=%" PRIu64 "\n", at_marker[1] - at_marker[0]);
    }
    if (fclose(report) != 0) {
        fprintf(stderr, "qemu-count: cannot write its report to %s\n", report_path);
    }
}

/* An address in C's notation (0x... for hexadecimal), nothing after it. */
static int parse_address(const char *text, uint64_t *address)
{
    char *end;
    if (*text == '\0') {
        return 0;
    }
    *address = strtoull(text, &end, 0);
    return *end == '\0';
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        const char *option = argv[i];
        if (strncmp(option, "out=", 4) == 0 && option[4] != '\0') {
            report_path = option + 4;
        } else if (strncmp(option, "marker=", 7) == 0 && parse_address(option + 7, &marker)) {
            has_marker = 1;
            /* Thumb symbols have bit 0 set; instructions sit at even addresses. */
            marker &= ~(uint64_t)1;
        } else {
            fprintf(stderr, "qemu-count: unknown option `%s` (expected out=PATH and marker=ADDRESS)\n", option);
            return -1;
        }
    }
    if (report_path == NULL) {
        fprintf(stderr, "qemu-count: no out=PATH for the report\n");
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, translated);
    qemu_plugin_register_atexit_cb(id, write_report, NULL);
    return 0;
}
