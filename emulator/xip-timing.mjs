// What an XIP cache miss costs: the QSPI transfer of one 8-byte cache line,
// in system clock cycles, from the SSI registers as the firmware's boot2
// left them (RP2040 datasheet, 2.6.3 "XIP" and 4.10 "SSI").
//
// The model. The SSI's serial clock is clk_sys / SCKDV (BAUDR; the SSI
// ignores its bit 0, so boot2s keep it even). A line is read as one
// transaction of
//
//   instruction  INST_L bits (0, 4, 8 or 16): on one lane, unless
//                TRANS_TYPE is 2C2A, when it goes over the frame format's
//                lanes. XIP in continuous-read mode sends none (INST_L 0):
//                the flash stays in its read command, and XIP_CMD goes out
//                as the mode bits after the address instead;
//   address      ADDR_L × 4 bits (address and mode bits): on one lane for
//                1C1A, else over the lanes;
//   wait         WAIT_CYCLES serial clocks with the data lines released;
//   data         64 bits (the line) over the lanes: 1 for standard SPI, 2
//                for dual, 4 for quad (CTRLR0.SPI_FRF),
//
// so it takes (instruction + address + wait + data clocks) × SCKDV cycles,
// plus RX_SAMPLE_DLY cycles: the SSI samples the last data bit that many
// ssi_clk cycles after its edge. The datasheet states no other fixed
// cost for a miss (a hit is "1 cycle", the bus access the core makes
// anyway), so there is none here.
//
// With rp2040-boot2's W25Q080 boot2 (SCKDV 2, quad, continuous read: no
// instruction, 32 address-and-mode bits over 4 lanes, 4 wait clocks):
// (0 + 8 + 4 + 16) × 2 + 1 = 57 cycles a miss.
//
// Invariant: a set-up the model cannot time (SSI clock off, a reserved
// frame format, double data rate) is an error naming the register, never a
// guess.

import { RunError } from './errors.mjs';

const INSTRUCTION_BITS = [0, 4, 8, 16];
const LANES = [1, 2, 4];
const TRANS_1C1A = 0;
const TRANS_2C2A = 2;
const LINE_BITS = 64;

/** The fields of SPI_CTRLR0 and CTRLR0 a transfer is made of. */
export function xipTransferFormat({ ctrlr0, spiCtrlr0 }) {
  const frameFormat = (ctrlr0 >>> 21) & 3;
  if (frameFormat === 3) {
    throw new RunError(`SSI CTRLR0 0x${ctrlr0.toString(16)}: SPI_FRF 3 is reserved`);
  }
  if (spiCtrlr0 & (1 << 16)) {
    throw new RunError(`SSI SPI_CTRLR0 0x${spiCtrlr0.toString(16)}: double data rate (SPI_DDR) is not modelled`);
  }
  const transType = spiCtrlr0 & 3;
  if (transType === 3) {
    throw new RunError(`SSI SPI_CTRLR0 0x${spiCtrlr0.toString(16)}: TRANS_TYPE 3 is reserved`);
  }
  return {
    lanes: LANES[frameFormat],
    transType,
    instructionBits: INSTRUCTION_BITS[(spiCtrlr0 >>> 8) & 3],
    addressBits: 4 * ((spiCtrlr0 >>> 2) & 0xf),
    waitClocks: (spiCtrlr0 >>> 11) & 0x1f,
    command: spiCtrlr0 >>> 24,
  };
}

/** The serial clock's period in system clock cycles (SCKDV, bit 0 ignored). */
export function serialClockCycles(baudr) {
  const divider = baudr & 0xfffe;
  if (divider === 0) {
    throw new RunError(`SSI BAUDR 0x${baudr.toString(16)}: the serial clock is off (SCKDV 0)`);
  }
  return divider;
}

/** Cycles a read of `dataBits` takes over the QSPI with these SSI registers (see the module's doc). */
export function transferCycles(registers, dataBits) {
  const format = xipTransferFormat(registers);
  const instructionLanes = format.transType === TRANS_2C2A ? format.lanes : 1;
  const addressLanes = format.transType === TRANS_1C1A ? 1 : format.lanes;
  const clocks =
    format.instructionBits / instructionLanes +
    format.addressBits / addressLanes +
    format.waitClocks +
    dataBits / format.lanes;
  return Math.ceil(clocks) * serialClockCycles(registers.baudr) + (registers.rxSampleDelay & 0xff);
}

/** Cycles one 8-byte cache line takes: what a miss stalls the reading core for. */
export function lineTransferCycles(registers) {
  return transferCycles(registers, LINE_BITS);
}
