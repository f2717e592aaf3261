"""The set-up logic of scripts/lib.sh, run against fake file trees.

A fresh Debian image ships /usr/lib/llvm-14/lib/libclang-cpp.so.14 (the C++
library) but not libclang: the old detection took the one for the other, never
installed libclang-dev, and bindgen then failed. These tests hold the detection
to what clang-sys (bindgen's loader) accepts, and check that the set-up asks for
libclang-dev exactly when no loadable libclang is there.
"""
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LIB_SH = ROOT / "scripts" / "lib.sh"
ELF = b"\x7fELF\x02\x01\x01" + b"\0" * 57  # an ELF header, enough for the magic check


def run(script, sysroot, **env):
    e = {k: v for k, v in os.environ.items() if k != "LIBCLANG_PATH"}
    e.update(KERF_SYSROOT=str(sysroot), **env)
    return subprocess.run(
        ["bash", "-c", f"source '{LIB_SH}'; {script}"],
        capture_output=True, text=True, env=e, timeout=60,
    )


def put(root, rel, data=ELF, link_to=None):
    p = root / rel.lstrip("/")
    p.parent.mkdir(parents=True, exist_ok=True)
    if link_to:
        p.symlink_to(link_to)
    else:
        p.write_bytes(data)
    return p


@pytest.fixture
def debian_fresh(tmp_path):
    """What the project's machine image has: LLVM and libclang-cpp, no libclang."""
    put(tmp_path, "/usr/lib/llvm-14/lib/libclang-cpp.so.14")
    put(tmp_path, "/usr/lib/llvm-14/lib/libLLVM-14.so.1")
    put(tmp_path, "/usr/lib/x86_64-linux-gnu/libclang-cpp.so.14")
    return tmp_path


def test_libclang_cpp_alone_is_not_libclang(debian_fresh):
    r = run("find_libclang", debian_fresh)
    assert r.returncode == 1, r.stdout
    assert r.stdout == ""


@pytest.mark.parametrize("rel", [
    "/usr/lib/llvm-14/lib/libclang.so.1",             # libclang1-14
    "/usr/lib/llvm-14/lib/libclang.so",               # libclang-14-dev
    "/usr/lib/x86_64-linux-gnu/libclang-14.so.1",     # libclang1-14's real file
    "/usr/lib/x86_64-linux-gnu/libclang-14.so.14.0.6",
    "/usr/local/lib/libclang.so",                     # a hand-built LLVM
])
def test_finds_the_library_bindgen_loads(debian_fresh, rel):
    want = put(debian_fresh, rel)
    r = run("find_libclang", debian_fresh)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(want)


def test_symlink_to_real_library_counts(debian_fresh):
    put(debian_fresh, "/usr/lib/x86_64-linux-gnu/libclang-14.so.1")
    put(debian_fresh, "/usr/lib/llvm-14/lib/libclang.so.1",
        link_to="../../x86_64-linux-gnu/libclang-14.so.1")
    assert run("find_libclang", debian_fresh).returncode == 0


def test_dangling_symlink_and_text_file_do_not_count(debian_fresh):
    # libclang-dev's libclang.so symlink without libclang1 behind it, and a linker script
    put(debian_fresh, "/usr/lib/llvm-14/lib/libclang.so", link_to="libclang.so.1")
    put(debian_fresh, "/usr/lib/x86_64-linux-gnu/libclang.so", data=b"/* GNU ld script */\n")
    assert run("find_libclang", debian_fresh).returncode == 1


def test_libclang_path_is_searched(debian_fresh, tmp_path_factory):
    elsewhere = tmp_path_factory.mktemp("llvm") / "lib"
    elsewhere.mkdir()
    (elsewhere / "libclang.so").write_bytes(ELF)
    r = run("find_libclang", debian_fresh, LIBCLANG_PATH=str(elsewhere))
    assert r.stdout.strip() == str(elsewhere / "libclang.so")


# ensure_system_deps with apt_install and cargo replaced by recorders
STUBS = (
    "apt_install() { echo \"APT $*\"; %s; };"
    "cargo() { :; }; cc() { :; };"
)


TBB = "/usr/lib/x86_64-linux-gnu/libtbb.so.12"


def test_fresh_image_installs_libclang_dev(debian_fresh):
    # apt_install "installs" libclang1 and libtbb12 into the fake tree, as apt-get would
    lib = debian_fresh / "usr/lib/llvm-14/lib/libclang.so.1"
    tbb = debian_fresh / TBB.lstrip("/")
    tbb.parent.mkdir(parents=True, exist_ok=True)
    stub = STUBS % f"printf '\\177ELF' > '{lib}'; printf '\\177ELF' > '{tbb}'"
    r = run(stub + "ensure_system_deps && echo DONE", debian_fresh)
    assert r.returncode == 0, r.stderr
    assert "APT libclang-dev libtbb12" in r.stdout
    assert r.stdout.strip().endswith("DONE")


def test_present_libclang_installs_nothing(debian_fresh):
    put(debian_fresh, "/usr/lib/llvm-14/lib/libclang.so.1")
    put(debian_fresh, TBB)
    r = run(STUBS % ":" + "ensure_system_deps && echo DONE", debian_fresh)
    assert r.returncode == 0, r.stderr
    assert "APT" not in r.stdout


def test_install_that_brings_no_libclang_fails_with_a_message(debian_fresh):
    r = run(STUBS % ":" + "ensure_system_deps && echo DONE", debian_fresh)
    assert r.returncode != 0
    assert "DONE" not in r.stdout
    assert "LIBCLANG_PATH" in r.stderr


# libtbb.so.12 (Debian libtbb12), which the Ecos host (PyPI ecospy) links against

@pytest.mark.parametrize("rel", [
    TBB,                                          # libtbb12 on amd64
    "/usr/lib/aarch64-linux-gnu/libtbb.so.12",    # libtbb12 on arm64
    "/usr/local/lib/libtbb.so.12.8",              # a hand-built oneTBB
])
def test_finds_libtbb(debian_fresh, rel):
    want = put(debian_fresh, rel)
    r = run("find_libtbb", debian_fresh)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(want)


def test_libtbb_symlink_counts_but_not_a_dangling_one_or_the_wrong_soname(debian_fresh):
    put(debian_fresh, TBB, link_to="libtbb.so.12.8")  # dangling
    put(debian_fresh, "/usr/lib/x86_64-linux-gnu/libtbb.so.2")  # old TBB 2020: another ABI
    assert run("find_libtbb", debian_fresh).returncode == 1
    put(debian_fresh, "/usr/lib/x86_64-linux-gnu/libtbb.so.12.8")
    assert run("find_libtbb", debian_fresh).returncode == 0


def test_missing_libtbb_alone_installs_libtbb12(debian_fresh):
    put(debian_fresh, "/usr/lib/llvm-14/lib/libclang.so.1")
    tbb = debian_fresh / TBB.lstrip("/")
    r = run(STUBS % f"printf '\\177ELF' > '{tbb}'" + "ensure_system_deps && echo DONE", debian_fresh)
    assert r.returncode == 0, r.stderr
    assert "APT libtbb12" in r.stdout
    assert "libclang-dev" not in r.stdout
    assert r.stdout.strip().endswith("DONE")


def test_install_that_brings_no_libtbb_fails_with_a_message(debian_fresh):
    put(debian_fresh, "/usr/lib/llvm-14/lib/libclang.so.1")
    r = run(STUBS % ":" + "ensure_system_deps && echo DONE", debian_fresh)
    assert r.returncode != 0
    assert "DONE" not in r.stdout
    assert "libtbb.so.12" in r.stderr
