# Shared setup for scripts/reference and scripts/test (sourced, not run).
# Installs only what is missing:
#   * libclang for bindgen (fmi-sys generates the FMI C bindings), via
#     apt-get install libclang-dev, only if no loadable libclang is found;
#   * libtbb.so.12 for the Ecos co-simulation host (PyPI ecospy, run by
#     tests/fmu/test_hosts.py), via apt-get install libtbb12, only if missing;
#   * .venv from the pinned requirements.txt, reinstalled only when that file
#     (or the Python version) changes - a hash stamp lives in .venv.
# Works as root without a tty (CI=true); as non-root it uses sudo for apt-get
# when available.

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
export PATH="${CARGO_HOME:-$HOME/.cargo}/bin:$PATH"
export PIP_DISABLE_PIP_VERSION_CHECK=1
export DEBIAN_FRONTEND=noninteractive

say() { printf '\n==> %s\n' "$*"; }
die() { printf '\nerror: %s\n' "$*" >&2; exit 1; }

apt_install() {
    local sudo=()
    if [ "$(id -u)" != 0 ]; then
        command -v sudo >/dev/null || die "need root (or sudo) to apt-get install $*"
        sudo=(sudo -n)
    fi
    command -v apt-get >/dev/null || die "apt-get not found; install $* by hand"
    say "apt-get install $*"
    "${sudo[@]}" apt-get update -q
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "$@"
}

# The libclang that bindgen (through clang-sys, loading at run time) accepts:
# a file named libclang.so, libclang-*.so, libclang.so.* or libclang-*.so.*,
# but not libclang-cpp* (the C++ library Debian's image ships without libclang),
# that is an ELF shared object, in $LIBCLANG_PATH, `llvm-config --libdir`, or the
# directories clang-sys searches on Linux. KERF_SYSROOT prefixes every system
# directory, so tests can run this against a fake file tree.
libclang_dirs() {
    local root="${KERF_SYSROOT:-}"
    [ -n "${LIBCLANG_PATH:-}" ] && printf '%s\n' "$LIBCLANG_PATH"
    if [ -z "$root" ] && command -v llvm-config >/dev/null 2>&1; then
        llvm-config --libdir 2>/dev/null
    fi
    local pat d
    for pat in '/usr/local/llvm*/lib*' '/usr/local/lib*/*/*' '/usr/local/lib*/*' '/usr/local/lib*' \
               '/usr/lib*/*/*' '/usr/lib*/*' '/usr/lib*'; do
        for d in $root$pat; do
            [ -d "$d" ] && printf '%s\n' "$d"
        done
    done
}

is_elf() { [ -f "$1" ] && [ "$(head -c 4 "$1" 2>/dev/null | od -An -c | tr -d ' ')" = '177ELF' ]; }

find_libclang() {
    local d f name
    local saved; saved="$(shopt -p nullglob)"
    shopt -s nullglob
    while IFS= read -r d; do
        for f in "$d"/libclang.so "$d"/libclang-*.so "$d"/libclang.so.* "$d"/libclang-*.so.*; do
            name="${f##*/}"
            case "$name" in *-cpp.*) continue ;; esac
            if is_elf "$f"; then
                eval "$saved"
                printf '%s\n' "$f"
                return 0
            fi
        done
    done < <(libclang_dirs)
    eval "$saved"
    return 1
}

have_libclang() { find_libclang >/dev/null; }

# The oneTBB runtime that ecospy's libecosc.so and `ecos` binary link against:
# libtbb.so.12 (Debian's libtbb12), an ELF file or a link to one, in the
# dynamic loader's usual directories (KERF_SYSROOT-prefixed, as above).
lib_dirs() {
    local root="${KERF_SYSROOT:-}" pat d
    for pat in '/usr/local/lib*/*' '/usr/local/lib*' '/usr/lib*/*' '/usr/lib*' '/lib*/*' '/lib*'; do
        for d in $root$pat; do
            [ -d "$d" ] && printf '%s\n' "$d"
        done
    done
}

find_libtbb() {
    local d f
    while IFS= read -r d; do
        for f in "$d"/libtbb.so.12 "$d"/libtbb.so.12.*; do
            if is_elf "$f"; then
                printf '%s\n' "$f"
                return 0
            fi
        done
    done < <(lib_dirs)
    return 1
}

have_libtbb() { find_libtbb >/dev/null; }

ensure_system_deps() {
    command -v cargo >/dev/null || die "cargo not found (install Rust: https://rustup.rs)"
    local pkgs=()
    have_libclang || pkgs+=(libclang-dev)
    have_libtbb || pkgs+=(libtbb12)
    command -v cc >/dev/null || pkgs+=(gcc libc6-dev)
    if [ ${#pkgs[@]} -gt 0 ]; then
        apt_install "${pkgs[@]}"
    fi
    have_libclang || die "no libclang that bindgen can load (libclang.so*, not libclang-cpp) after installing libclang-dev; set LIBCLANG_PATH"
    have_libtbb || die "no libtbb.so.12 (for the Ecos host) after installing libtbb12"
}

find_python() {
    local c
    for c in "${PYTHON:-}" python3.11 python3; do
        [ -n "$c" ] || continue
        if command -v "$c" >/dev/null && "$c" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
            echo "$c"; return 0
        fi
    done
    return 1
}

ensure_venv() {
    local py stamp want
    py="$(find_python)" || die "Python >= 3.11 not found (set PYTHON=...)"
    want="$(cat "$ROOT/requirements.txt" <("$py" -c 'import sys; print(sys.version)') | sha256sum | cut -d' ' -f1)"
    stamp="$VENV/.kerf-requirements.sha256"
    if [ -x "$PY" ] && "$PY" -c 'pass' 2>/dev/null && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        return 0
    fi
    if ! { [ -x "$PY" ] && "$PY" -c 'pass' 2>/dev/null; }; then
        say "creating $VENV with $py"
        rm -rf "$VENV"
        if ! "$py" -m venv "$VENV" 2>/dev/null; then
            # Debian's python3 lacks ensurepip without the python3-venv package
            rm -rf "$VENV"
            local v; v="$("$py" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
            apt_install "python${v}-venv" || apt_install python3-venv
            "$py" -m venv "$VENV" || die "could not create $VENV"
        fi
    fi
    say "installing pinned requirements.txt into $VENV"
    "$PY" -m pip install -q -r "$ROOT/requirements.txt" || die "pip install -r requirements.txt failed"
    echo "$want" > "$stamp"
}

build_fmu() {
    say "cargo run --release -p packaging"
    (cd "$ROOT" && cargo run --release -p packaging) || die "packaging failed"
    [ -f "$ROOT/target/fmu/kerf.fmu" ] || die "packaging did not write target/fmu/kerf.fmu"
}
