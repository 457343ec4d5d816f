// Reads a 32-bit little-endian ARM ELF as `cargo build` writes it: the
// segments to load (at their load addresses, so `.data` lands in flash where
// the start-up code copies it from) and the function symbols, to name where
// a firmware stopped.
//
// Invariant: anything that is not such an ELF is an error naming the file and
// what was found, never a partial load.

const PT_LOAD = 1;
const SHT_SYMTAB = 2;
const STT_FUNC = 2;
const EM_ARM = 40;

export class ElfError extends Error {}

/** Parses `bytes` (a Buffer) read from `path`. */
export function parseElf(bytes, path) {
  const fail = (what) => {
    throw new ElfError(`${path}: ${what}`);
  };
  if (bytes.length < 52 || bytes.readUInt32BE(0) !== 0x7f454c46) {
    fail('not an ELF file');
  }
  if (bytes[4] !== 1 || bytes[5] !== 1) {
    fail(`expected a 32-bit little-endian ELF, found class ${bytes[4]}, data ${bytes[5]}`);
  }
  const machine = bytes.readUInt16LE(18);
  if (machine !== EM_ARM) {
    fail(`expected an ARM ELF (machine ${EM_ARM}), found machine ${machine}`);
  }
  const field = (offset, size) => {
    if (offset + size > bytes.length) {
      fail(`truncated: needs ${offset + size} bytes, has ${bytes.length}`);
    }
    return bytes.subarray(offset, offset + size);
  };

  const phoff = bytes.readUInt32LE(28);
  const phentsize = bytes.readUInt16LE(42);
  const phnum = bytes.readUInt16LE(44);
  const segments = [];
  for (let i = 0; i < phnum; i++) {
    const header = field(phoff + i * phentsize, 32);
    if (header.readUInt32LE(0) !== PT_LOAD) {
      continue;
    }
    const offset = header.readUInt32LE(4);
    const loadAddress = header.readUInt32LE(12);
    const fileSize = header.readUInt32LE(16);
    if (fileSize > 0) {
      segments.push({ loadAddress, data: field(offset, fileSize) });
    }
  }
  if (segments.length === 0) {
    fail('no loadable segment');
  }

  const shoff = bytes.readUInt32LE(32);
  const shentsize = bytes.readUInt16LE(46);
  const shnum = bytes.readUInt16LE(48);
  const section = (i) => {
    const header = field(shoff + i * shentsize, 40);
    return {
      type: header.readUInt32LE(4),
      offset: header.readUInt32LE(16),
      size: header.readUInt32LE(20),
      link: header.readUInt32LE(24),
      entrySize: header.readUInt32LE(36),
    };
  };
  const functions = [];
  for (let i = 0; i < shnum; i++) {
    const symtab = section(i);
    if (symtab.type !== SHT_SYMTAB) {
      continue;
    }
    const strtab = section(symtab.link);
    const names = field(strtab.offset, strtab.size);
    const entries = field(symtab.offset, symtab.size);
    for (let at = 0; at + 16 <= entries.length; at += symtab.entrySize || 16) {
      if ((entries[at + 12] & 0xf) !== STT_FUNC) {
        continue;
      }
      const nameAt = entries.readUInt32LE(at);
      const end = names.indexOf(0, nameAt);
      functions.push({
        name: names.toString('utf8', nameAt, end < 0 ? names.length : end),
        address: entries.readUInt32LE(at + 4) & ~1,
        size: entries.readUInt32LE(at + 8),
      });
    }
  }
  functions.sort((a, b) => a.address - b.address);
  return { segments, functions };
}

/** The name of the function holding `address`, or its address in hex. */
export function functionAt(functions, address) {
  let found = null;
  for (const f of functions) {
    if (f.address > address) {
      break;
    }
    if (address < f.address + Math.max(f.size, 2)) {
      found = f;
    }
  }
  const hex = `0x${(address >>> 0).toString(16).padStart(8, '0')}`;
  return found ? `${found.name} (${hex})` : hex;
}

/**
 * The name of the function holding `address` (demangled, `demangle`), or
 * `?` — by bisection, for a profile's many lookups (`functions` sorted by
 * address, as `parseElf` gives them).
 */
export function functionNameAt(functions, address) {
  let lo = 0;
  let hi = functions.length - 1;
  let found = -1;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    if (functions[mid].address <= address) {
      found = mid;
      lo = mid + 1;
    } else {
      hi = mid - 1;
    }
  }
  const f = functions[found];
  if (!f || address >= f.address + Math.max(f.size, 2)) return '?';
  return (f.demangled ??= demangle(f.name));
}

/** Rust's legacy mangling (`_ZN` + lengthed parts + `E`) read back, its hash dropped; any other name as it is. */
export function demangle(name) {
  const match = /^_?_ZN(.*)E$/.exec(name);
  if (!match) return name;
  const parts = [];
  let rest = match[1];
  while (rest.length > 0) {
    const length = /^\d+/.exec(rest);
    if (!length) return name;
    parts.push(rest.slice(length[0].length, length[0].length + Number(length[0])));
    rest = rest.slice(length[0].length + Number(length[0]));
  }
  if (parts.length > 1 && /^h[0-9a-f]{16}$/.test(parts.at(-1))) parts.pop();
  const escapes = { SP: '@', BP: '*', RF: '&', LT: '<', GT: '>', LP: '(', RP: ')', C: ',' };
  return parts
    .map((part) =>
      part
        .replace(/^_\$/, '$')
        .replace(/\$([A-Z]{1,2})\$/g, (all, code) => escapes[code] ?? all)
        .replace(/\$u([0-9a-f]+)\$/g, (_, hex) => String.fromCodePoint(parseInt(hex, 16)))
        .replace(/\.\./g, '::'),
    )
    .join('::');
}
