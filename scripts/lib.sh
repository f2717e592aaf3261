# Shared setup for scripts/reference and scripts/test (sourced, not run).
# Installs only what is missing:
#   * libclang (+ clang) for bindgen, via apt-get, only if no libclang is found;
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

have_libclang() {
    compgen -G '/usr/lib/llvm-*/lib/libclang*.so*' >/dev/null && return 0
    [ -n "${LIBCLANG_PATH:-}" ] && compgen -G "$LIBCLANG_PATH/libclang*.so*" >/dev/null && return 0
    ldconfig -p 2>/dev/null | grep -q 'libclang[-.0-9]*\.so' && return 0
    return 1
}

ensure_system_deps() {
    command -v cargo >/dev/null || die "cargo not found (install Rust: https://rustup.rs)"
    local pkgs=()
    have_libclang || pkgs+=(libclang-dev clang)
    command -v cc >/dev/null || pkgs+=(gcc libc6-dev)
    if [ ${#pkgs[@]} -gt 0 ]; then
        apt_install "${pkgs[@]}"
    fi
    have_libclang || die "libclang still not found after installing libclang-dev"
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
