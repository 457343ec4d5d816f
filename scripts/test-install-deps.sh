#!/usr/bin/env bash
# Tests the install step of scripts/test-all (scripts/install-test-deps.sh)
# without root and without apt: a fake apt-get, apt-cache, sudo and id on PATH
# answer as apt did on a Debian 12 machine whose qemu-utils came from
# bookworm-backports (issue 35), and as it does on other refusals. Also checks
# that docs/tests.md names everything the install step installs.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/install-test-deps.sh

fake="$(mktemp -d)"
trap 'rm -r "$fake"' EXIT
mkdir "$fake/bin"
export FAKE_DIR="$fake" PATH="$fake/bin:$PATH"

cat >"$fake/bin/id" <<'EOF'
#!/usr/bin/env bash
echo "${FAKE_UID:-1000}"
EOF
cat >"$fake/bin/sudo" <<'EOF'
#!/usr/bin/env bash
printf 'sudo ' >>"$FAKE_DIR/apt.log"
exec "$@"
EOF
# apt-get as it answered in each case, $FAKE_APT naming the case. Accepting an
# install, it "installs" the commands of the packages asked for.
cat >"$fake/bin/apt-get" <<'EOF'
#!/usr/bin/env bash
printf 'apt-get %s\n' "$*" >>"$FAKE_DIR/apt.log"
args=" $* "
if [[ $args == *" update "* ]]; then
    [ "$FAKE_APT" != offline ] && exit 0
    echo 'E: Failed to fetch http://deb.debian.org/debian/dists/bookworm/InRelease  Temporary failure resolving '"'"'deb.debian.org'"'"'' >&2
    exit 100
fi
case $FAKE_APT in
backports)
    if [[ $args != *" --allow-downgrades qemu-utils=1:7.2+dfsg-7+deb12u18+b3 "* ]]; then
        # As apt does, -qq hides the lines that say why.
        [[ $args == *" -qq "* ]] && exec >/dev/null
        cat <<'APT'
Reading package lists...
Building dependency tree...
Reading state information...
Some packages could not be installed. This may mean that you have
requested an impossible situation or if you are using the unstable
distribution that some required packages have not yet been created
or been moved out of Incoming.
The following information may help to resolve the situation:

The following packages have unmet dependencies:
 qemu-utils : Breaks: qemu-system-common (< 1:8.0+dfsg-5~) but 1:7.2+dfsg-7+deb12u18+b3 is to be installed
              Recommends: qemu-block-extra (= 1:10.0.2+ds-2+deb13u1~bpo12+1) but 1:7.2+dfsg-7+deb12u18+b3 is to be installed
APT
        echo 'E: Error, pkgProblemResolver::Resolve generated breaks, this may be caused by held packages.' >&2
        exit 100
    fi ;;
newer-library)
    if [[ $args != *" --allow-downgrades libfdt1=1.6.1-4+b1 "* ]]; then
        printf '%s\n' 'The following packages have unmet dependencies:' \
            ' qemu-system-arm : Depends: libfdt1 (< 1.7.0) but 1.7.2-1~bpo12+1 is installed'
        echo 'E: Unable to correct problems, you have held broken packages.' >&2
        exit 100
    fi ;;
locked)
    printf '%s\n' 'Reading package lists...' 'Building dependency tree...' 'Reading state information...'
    echo 'E: Could not get lock /var/lib/dpkg/lock-frontend. It is held by process 4242 (apt-get)' >&2
    exit 100 ;;
installs-nothing)
    exit 0 ;;
esac
[[ $args == *" --simulate "* ]] && exit 0
for package in "$@"; do
    case $package in
    qemu-system-arm) touch "$FAKE_DIR/bin/octrace-test-qemu-system-arm" ;;
    qemu-system-misc) touch "$FAKE_DIR/bin/octrace-test-qemu-system-riscv32" ;;
    esac
done
chmod +x "$FAKE_DIR"/bin/octrace-test-*
EOF
# apt-cache as on that machine: qemu-utils and libfdt1 from backports installed,
# the rest offered by bookworm and bookworm-security.
cat >"$fake/bin/apt-cache" <<'EOF'
#!/usr/bin/env bash
bookworm='http://deb.debian.org/debian bookworm/main amd64 Packages'
security='http://deb.debian.org/debian-security bookworm-security/main amd64 Packages'
case "$1 $2" in
"policy qemu-utils") printf '%s:\n  Installed: %s\n  Candidate: %s\n' "$2" 1:10.0.2+ds-2+deb13u1~bpo12+1 1:10.0.2+ds-2+deb13u1~bpo12+1 ;;
"policy libfdt1") printf '%s:\n  Installed: %s\n  Candidate: %s\n' "$2" 1.7.2-1~bpo12+1 1.7.2-1~bpo12+1 ;;
"policy "*) printf '%s:\n  Installed: (none)\n  Candidate: %s\n' "$2" 1:7.2+dfsg-7+deb12u18+b3 ;;
"madison libfdt1") printf '%10s | %s | %s\n' "$2" 1.6.1-4+b1 "$bookworm" ;;
"madison "*) printf '%10s | %s | %s\n' "$2" 1:7.2+dfsg-7+deb12u18+b3 "$bookworm" "$2" 1:7.2+dfsg-7+deb12u15 "$security" ;;
esac
EOF
chmod +x "$fake"/bin/*
touch "$fake/bin/octrace-test-present" && chmod +x "$fake/bin/octrace-test-present"

failures=0 cases=0
fail() {
    printf 'test-install-deps: %s: %s\n--- what it printed:\n%s\n--- what apt was asked:\n%s\n---\n' \
        "$case_name" "$1" "$output" "$(cat "$fake/apt.log" 2>/dev/null)" >&2
    failures=$((failures + 1))
}
# run CASE APT_CASE [--allow-downgrades]: the install step of the two qemu
# commands (missing) and one command that is there.
run() {
    case_name=$1 && export FAKE_APT=$2 && shift 2 && cases=$((cases + 1))
    rm -f "$fake/apt.log" "$fake"/bin/octrace-test-qemu-*
    status=0
    output=$(install_missing_commands "$@" octrace-test-qemu-system-arm:qemu-system-arm \
        octrace-test-qemu-system-riscv32:qemu-system-misc octrace-test-present:parallel 2>&1) || status=$?
}
says() { grep -qxF -- "$1" <<<"$output" || fail "no line '$1'"; }
asked() { grep -qxF -- "$1" "$fake/apt.log" 2>/dev/null || fail "apt was not asked '$1'"; }
not_asked() { ! grep -qF -- "$1" "$fake/apt.log" 2>/dev/null || fail "apt was asked '$1'"; }
failed() { [ "$status" -ne 0 ] || fail "returned 0"; }
succeeded() { [ "$status" -eq 0 ] || fail "returned $status"; }
installed() { [ -x "$fake/bin/octrace-test-qemu-system-arm" ] && [ -x "$fake/bin/octrace-test-qemu-system-riscv32" ] || fail "the commands are not installed"; }
says_who_and_what() {
    says 'test-all: apt could not install what the tests need.'
    says '  Commands missing:   octrace-test-qemu-system-arm octrace-test-qemu-system-riscv32'
    says '  Packages asked for: qemu-system-arm qemu-system-misc'
    says "  apt's reason:"
}

run "the backports conflict" backports
failed
says_who_and_what
says '     qemu-utils : Breaks: qemu-system-common (< 1:8.0+dfsg-5~) but 1:7.2+dfsg-7+deb12u18+b3 is to be installed'
says '    E: Error, pkgProblemResolver::Resolve generated breaks, this may be caused by held packages.'
says '  The conflict: qemu-utils 1:10.0.2+ds-2+deb13u1~bpo12+1 is installed, newer than the 1:7.2+dfsg-7+deb12u18+b3 that goes with the packages asked for.'
says '    sudo apt-get install --allow-downgrades qemu-utils=1:7.2+dfsg-7+deb12u18+b3 qemu-system-arm qemu-system-misc'
says '  A downgrade is yours to decide, so test-all runs it only when asked: bash scripts/test-all --allow-downgrades'
asked 'sudo apt-get install -y -q qemu-system-arm qemu-system-misc'
asked 'apt-get --simulate -q install --allow-downgrades qemu-utils=1:7.2+dfsg-7+deb12u18+b3 qemu-system-arm qemu-system-misc'
not_asked '-y -q install --allow-downgrades'

run "the backports conflict, --allow-downgrades" backports --allow-downgrades
succeeded
asked 'sudo apt-get -y -q install --allow-downgrades qemu-utils=1:7.2+dfsg-7+deb12u18+b3 qemu-system-arm qemu-system-misc'
installed

FAKE_UID=0 run "the backports conflict, as root" backports
says '    apt-get install --allow-downgrades qemu-utils=1:7.2+dfsg-7+deb12u18+b3 qemu-system-arm qemu-system-misc'
not_asked 'sudo'

run "a newer installed library the candidate depends on, from its suite" newer-library
failed
says '  The conflict: libfdt1 1.7.2-1~bpo12+1 is installed, newer than the 1.6.1-4+b1 that goes with the packages asked for.'
says '    sudo apt-get install --allow-downgrades libfdt1=1.6.1-4+b1 qemu-system-arm qemu-system-misc'

for flag in "" --allow-downgrades; do
    run "another refusal ${flag:-(no flag)}" locked ${flag:+"$flag"}
    failed
    says_who_and_what
    says '    E: Could not get lock /var/lib/dpkg/lock-frontend. It is held by process 4242 (apt-get)'
    says '    sudo apt-get install qemu-system-arm qemu-system-misc'
    ! grep -qF 'Reading package lists' <<<"$output" || fail "apt's progress is not its reason"
    not_asked '--allow-downgrades'
done

run "apt cannot read its package lists" offline
failed
says_who_and_what
says "    E: Failed to fetch http://deb.debian.org/debian/dists/bookworm/InRelease  Temporary failure resolving 'deb.debian.org'"
says '  apt could not read its package lists; once it can, run scripts/test-all again.'
not_asked 'install'

run "apt succeeds but the commands do not appear" installs-nothing
failed
says 'test-all: apt installed qemu-system-arm qemu-system-misc, yet these commands the tests run are still missing: octrace-test-qemu-system-arm octrace-test-qemu-system-riscv32'

case_name="nothing missing" output="" status=0
rm -f "$fake/apt.log"
install_missing_commands octrace-test-present:parallel || status=$?
succeeded
[ ! -e "$fake/apt.log" ] || fail "apt was called"

documented="$(awk '/^## What the test command installs$/ { on = 1; next } /^## / { on = 0 } on' docs/tests.md)"
for name in "${TEST_RUST_COMPONENTS[@]}" "${TEST_RUST_TARGETS[@]}" "${TEST_COMMAND_PACKAGES[@]#*:}" "${TEST_COMMAND_PACKAGES[@]%%:*}"; do
    grep -qF -- "\`$name\`" <<<"$documented" ||
        { echo "test-install-deps: docs/tests.md's list of what the test command installs does not name \`$name\`, which test-all installs" >&2 && failures=$((failures + 1)); }
done

[ "$failures" -eq 0 ] || exit 1
echo "test-install-deps: the install step against a fake apt ($cases cases, and one with nothing missing), docs/tests.md's list"
