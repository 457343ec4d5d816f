# shellcheck shell=bash
# What octrace's tests need, and the apt step that installs the missing part
# of it, with a diagnosis of its own when apt refuses.
# Sourced by scripts/test-all (and by scripts/test-install-deps.sh, which runs
# the apt step against a fake apt); it only defines variables and functions.
# docs/tests.md names everything listed here (scripts/test-install-deps.sh checks it).

# The rustup components and targets the suite builds with (rust-toolchain.toml
# names the same).
# shellcheck disable=SC2034 # the lists are for the scripts that source this file
TEST_RUST_COMPONENTS=(rustfmt clippy)
TEST_RUST_TARGETS=(thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf thumbv8m.main-none-eabihf
    riscv32imc-unknown-none-elf wasm32-unknown-unknown)

# Each command the tests run and the Debian package that brings it, one pair a line.
TEST_COMMAND_PACKAGES=(
    qemu-system-arm:qemu-system-arm
    qemu-system-riscv32:qemu-system-misc
    gcc:gcc
    arm-none-eabi-size:binutils-arm-none-eabi
    parallel:parallel
    /usr/bin/chromium:chromium
    /usr/bin/chromedriver:chromium-driver
    ffprobe:ffmpeg
    ffmpeg:ffmpeg
    node:nodejs
    npm:npm
    python3:python3
)

# install_missing_commands [--allow-downgrades] COMMAND:PACKAGE...
# Installs with apt the packages of the commands that are missing, and returns
# 0 only when every command is there afterwards. When apt refuses, it says
# which commands are missing, which packages it asked for and apt's reason;
# when the reason is an installed package newer than the suite that offers
# the others (say a qemu-utils from bookworm-backports beside bookworm's
# qemu-system-arm), it prints the downgrade that resolves it, checked with
# apt's --simulate. A downgrade of a system package is the user's call, so it
# runs that downgrade itself only under --allow-downgrades.
install_missing_commands() {
    local allow_downgrades=no
    if [ "${1-}" = --allow-downgrades ]; then
        allow_downgrades=yes
        shift
    fi
    local pair commands=() packages=()
    for pair in "$@"; do
        command -v "${pair%%:*}" >/dev/null && continue
        commands+=("${pair%%:*}")
        # Two commands may come from one package: ask for it once.
        [[ " ${packages[*]} " == *" ${pair#*:} "* ]] || packages+=("${pair#*:}")
    done
    [ ${#packages[@]} -gt 0 ] || return 0

    local sudo="" output
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    if ! output=$(${sudo:+"$sudo"} apt-get update -qq 2>&1); then
        report_apt_refusal "$output" "${commands[*]}" "${packages[*]}"
        printf '  apt could not read its package lists; once it can, run scripts/test-all again.\n' >&2
        return 1
    fi
    # -q, not -qq: -qq also hides the "unmet dependencies" lines the diagnosis reads.
    if ! output=$(${sudo:+"$sudo"} apt-get install -y -q "${packages[@]}" 2>&1); then
        report_apt_refusal "$output" "${commands[*]}" "${packages[*]}"
        local culprit installed wanted downgrades=()
        while read -r culprit installed wanted; do
            printf '  The conflict: %s %s is installed, newer than the %s that goes with the packages asked for.\n' \
                "$culprit" "$installed" "$wanted" >&2
            downgrades+=("$culprit=$wanted")
        done < <(apt_newer_installed_siblings "$output")
        local remedy=(install --allow-downgrades "${downgrades[@]}" "${packages[@]}")
        if [ ${#downgrades[@]} -eq 0 ] || ! apt-get --simulate -q "${remedy[@]}" >/dev/null 2>&1; then
            printf '  Once what apt says above is cleared, install them by hand (docs/tests.md):\n    %s\n' \
                "${sudo:+sudo }apt-get install ${packages[*]}" >&2
            return 1
        fi
        if [ "$allow_downgrades" = no ]; then
            printf '  This resolves it (apt --simulate accepts it):\n    %s\n' "${sudo:+sudo }apt-get ${remedy[*]}" >&2
            printf '  A downgrade is yours to decide, so test-all runs it only when asked: bash scripts/test-all --allow-downgrades\n' >&2
            return 1
        fi
        printf 'test-all: --allow-downgrades: %s\n' "${sudo:+sudo }apt-get ${remedy[*]}" >&2
        if ! output=$(${sudo:+"$sudo"} apt-get -y -q "${remedy[@]}" 2>&1); then
            report_apt_refusal "$output" "${commands[*]}" "${packages[*]}"
            return 1
        fi
    fi

    local command still_missing=()
    for command in "${commands[@]}"; do
        command -v "$command" >/dev/null || still_missing+=("$command")
    done
    if [ ${#still_missing[@]} -gt 0 ]; then
        printf 'test-all: apt installed %s, yet these commands the tests run are still missing: %s\n' \
            "${packages[*]}" "${still_missing[*]}" >&2
        return 1
    fi
}

# report_apt_refusal APT_OUTPUT COMMANDS PACKAGES: the first lines of the
# diagnosis: what is missing, what was asked for, and apt's own reason (its
# errors and unmet-dependency lines, or else its last lines).
report_apt_refusal() {
    local reason
    reason=$(printf '%s\n' "$1" | awk '/unmet dependencies/ { on = 1 } on || /^[EW]: /')
    [ -n "$reason" ] || reason=$(printf '%s\n' "$1" | tail -n 5)
    {
        printf 'test-all: apt could not install what the tests need.\n'
        printf '  Commands missing:   %s\n' "$2"
        printf '  Packages asked for: %s\n' "$3"
        printf "  apt's reason:\n"
        printf '%s\n' "$reason" | sed 's/^/    /'
    } >&2
}

# apt_newer_installed_siblings APT_OUTPUT: reads apt's unmet-dependency
# lines ("X : Breaks: Y (< V) but W is to be installed", "X : Depends: Y (< V)
# but W is installed", ...) and prints, once per package, "PACKAGE INSTALLED
# WANTED" for each installed package that stands in the way because it is
# newer than its sibling in the line; WANTED is its version in the suite that
# offers the sibling's version.
apt_newer_installed_siblings() {
    local seen=" " line left="" relation right version but culprit sibling sibling_version installed suite wanted
    local pattern='(Pre-?Depends|Depends|Recommends|Breaks|Conflicts): ([^ ]+) \([<>=!]+ ([^ )]+)\) but ([^ ]+) is (to be )?installed'
    while IFS= read -r line; do
        [[ $line =~ ^\ *([^ ]+)\ :\  ]] && left=${BASH_REMATCH[1]}
        [[ -n $left && $line =~ $pattern ]] || continue
        relation=${BASH_REMATCH[1]} right=${BASH_REMATCH[2]} version=${BASH_REMATCH[3]} but=${BASH_REMATCH[4]}
        if [[ $relation != Breaks && $relation != Conflicts ]] && dpkg --compare-versions "$but" gt "$version"; then
            # The left package needs an older right one: the right one is the newer sibling.
            culprit=$right sibling=$left
            sibling_version=$(apt_policy_version "$left" Candidate)
        else
            # The left package breaks, or needs a newer, right one as apt would install it.
            culprit=$left sibling=$right sibling_version=$but
        fi
        [[ $seen != *" $culprit "* ]] || continue
        installed=$(apt_policy_version "$culprit" Installed)
        [[ -n $installed && $installed != "(none)" ]] || continue
        suite=$(apt_madison "$sibling" | awk -F'\t' -v v="$sibling_version" '$1 == v { print $2; exit }')
        wanted=$(apt_madison "$culprit" | awk -F'\t' -v s="$suite" 's != "" && $2 == s { print $1; exit }')
        [[ -n $wanted && $wanted != "$installed" ]] || continue
        seen+="$culprit "
        printf '%s %s %s\n' "$culprit" "$installed" "$wanted"
    done <<<"$1"
}

# apt_policy_version PACKAGE Installed|Candidate: that line of apt-cache policy.
apt_policy_version() {
    apt-cache policy "$1" 2>/dev/null | awk -v key="$2:" '$1 == key { print $2; exit }'
}

# apt_madison PACKAGE: "VERSION<tab>SOURCE SUITE" for each binary version the
# sources offer (the archive's address and suite/component, without the
# architecture, so an arch-all sibling matches).
apt_madison() {
    apt-cache madison "$1" 2>/dev/null | awk -F'|' -v p="$1" '
        { for (i = 1; i <= 3; i++) gsub(/^ +| +$/, "", $i) }
        $1 == p && $3 ~ / Packages$/ { split($3, where, " "); print $2 "\t" where[1] " " where[2] }'
}
