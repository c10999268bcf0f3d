"""Restarting a checkpoint of another dimension, engine or rank count than the one that reads it
(docs/robustness.md, "Files from outside"): every mismatch is exit 2 with a message that names the
checkpoint and what disagrees; a checkpoint written on 2 MPI ranks restarts on one.

The checkpoints are the seeds of cairn_fuzz_checkpoint (tests/robustness/corpus/checkpoint/seeds),
edited with h5py: the content checksum is deleted, as a file written before checksums has none, so
that the reader's own checks are reached.

Usage: /usr/bin/python3 test_restart_mismatch.py <cairn binary> <source dir>
"""
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)
    print("  ok:", message)


def restart(cairn, checkpoint, *sets, expect=2):
    args = [cairn, "restart", "-q", "-t", "1", checkpoint]
    for s in sets:
        args += ["--set", s]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=300)
    if proc.returncode != expect:
        raise CheckFailed(f"'{' '.join(args[1:])}' exited with {proc.returncode}, expected {expect}\n"
                          f"--- stderr ---\n{proc.stderr}")
    return proc.stderr


def edited(seeds, tmp, seed, name, edit):
    """A copy of the seed checkpoint `seed`, without its checksum, changed by edit(file)."""
    path = os.path.join(tmp, name)
    shutil.copy(os.path.join(seeds, seed), path)
    with h5py.File(path, "r+") as f:
        if "checksum" in f.attrs:
            del f.attrs["checksum"]
        edit(f)
    return path


def set_text(f, name, text):
    """Replace the scalar fixed-length string dataset `name` (the stored input)."""
    del f[name]
    data = text.encode()
    f.create_dataset(name, data=np.array(data, dtype=h5py.string_dtype("ascii", len(data))))


def stored_input(seeds, seed, name):
    with h5py.File(os.path.join(seeds, seed), "r") as f:
        return f[name][()].decode()


def says(err, path, *words):
    return path in err and all(w in err for w in words)


def dimensions(cairn, seeds, tmp):
    # The dimension attribute against the particles and the input stored with them.
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "2d_says_3d.h5", lambda f: f.attrs.modify("dimension", 3))
    err = restart(cairn, path)
    check(says(err, path, "dimension", "3D", "2D"), f"a 2D checkpoint whose dimension says 3: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "mpm_3d_apic_thermal.h5", "3d_says_2d.h5", lambda f: f.attrs.modify("dimension", 2))
    err = restart(cairn, path)
    check(says(err, path, "dimension", "3D", "2D"), f"a 3D checkpoint whose dimension says 2: exit 2, {err.strip()!r}")
    three = stored_input(seeds, "mpm_3d_apic_thermal.h5", "config_toml")
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "2d_with_3d_input.h5", lambda f: set_text(f, "config_toml", three))
    err = restart(cairn, path)
    check(says(err, path, "dimension", "3D", "2D"), f"2D particles with a 3D input: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "mpm_1d.h5", "1d_says_4d.h5", lambda f: f.attrs.modify("dimension", 4))
    err = restart(cairn, path)
    check(says(err, path, "dimension", "4"), f"dimension 4: exit 2, {err.strip()!r}")
    # --set cannot change it either (a key that made the stored state).
    path = os.path.join(tmp, "plain_2d.h5")
    shutil.copy(os.path.join(seeds, "mpm_2d_contact.h5"), path)
    err = restart(cairn, path, "simulation.dimension=3")
    check("simulation.dimension" in err, f"--set simulation.dimension=3: exit 2, {err.strip()!r}")


def engines(cairn, seeds, tmp):
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "mpm_says_fem.h5", lambda f: f.attrs.modify("engine", "fem"))
    err = restart(cairn, path)
    check(says(err, path, "fem", "cairn-checkpoint"), f"an MPM checkpoint whose engine says fem: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "fem_2d.h5", "fem_says_mpm.h5", lambda f: f.attrs.modify("engine", "mpm"))
    err = restart(cairn, path)
    check(says(err, path, "mpm", "cairn-fem-checkpoint"), f"an FEM checkpoint whose engine says mpm: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "mpm_says_wls.h5", lambda f: f.attrs.modify("engine", "wls"))
    err = restart(cairn, path)
    check(says(err, path, "engine", "wls", "mpm"), f"an MPM checkpoint whose engine says wls: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "wls_2d.h5", "wls_says_mpm.h5", lambda f: f.attrs.modify("engine", "mpm"))
    err = restart(cairn, path)
    check(says(err, path, "engine", "wls", "mpm"), f"a WLS checkpoint whose engine says mpm: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "engine_xyz.h5", lambda f: f.attrs.modify("engine", "xyz"))
    err = restart(cairn, path)
    check(says(err, path, "engine", "xyz"), f"an unknown engine: exit 2, {err.strip()!r}")
    mpm = stored_input(seeds, "mpm_2d_contact.h5", "config_toml")
    path = edited(seeds, tmp, "fem_2d.h5", "fem_with_mpm_input.h5", lambda f: set_text(f, "input", mpm))
    err = restart(cairn, path)
    check(says(err, path, "fem", "mpm"), f"an FEM checkpoint holding an MPM input: exit 2, {err.strip()!r}")
    fem = stored_input(seeds, "fem_2d.h5", "input")
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "mpm_with_fem_input.h5", lambda f: set_text(f, "config_toml", fem))
    err = restart(cairn, path)
    check(says(err, path, "engine", "fem", "mpm"), f"an MPM checkpoint holding an FEM input: exit 2, {err.strip()!r}")


def contact_record(cairn, seeds, tmp):
    # /contact/in_contact ([contact] release = "separation"): keys of the stored grid's nodes and
    # contact fields only.
    for key in (1 << 60, -1):
        path = edited(seeds, tmp, "mpm_2d_contact.h5", f"contact_key_{key}.h5",
                      lambda f: f.create_dataset("contact/in_contact", data=np.array([3, key], dtype=np.int64)))
        err = restart(cairn, path)
        check(says(err, path, "/contact/in_contact", f"the key {key}"), f"a contact record key {key}: exit 2, {err.strip()!r}")
    path = edited(seeds, tmp, "mpm_2d_contact.h5", "contact_record_2d.h5",
                  lambda f: f.create_dataset("contact/in_contact", data=np.zeros((2, 2), dtype=np.int64)))
    err = restart(cairn, path)
    check(says(err, path, "/contact/in_contact", "1D"), f"a 2D contact record: exit 2, {err.strip()!r}")


def ranks(cairn, seeds, tmp):
    # Particles stored rank after rank by 2 ranks restart on one, to the next step.
    folder = os.path.join(tmp, "ranks")
    os.makedirs(folder)
    path = os.path.join(folder, "checkpoint-0000.h5")
    shutil.copy(os.path.join(seeds, "mpm_2d_contact_2ranks.h5"), path)
    restart(cairn, path, "simulation.max_steps=4", expect=0)
    check(os.path.exists(os.path.join(folder, "history.csv")), "a checkpoint of 2 ranks restarts on one rank")


def main():
    if len(sys.argv) < 3:
        print("usage: test_restart_mismatch.py <cairn binary> <source dir>", file=sys.stderr)
        return 2
    cairn = os.path.abspath(sys.argv[1])
    seeds = os.path.join(sys.argv[2], "tests/robustness/corpus/checkpoint/seeds")
    with tempfile.TemporaryDirectory(prefix="cairn_restart_mismatch_") as tmp:
        try:
            for case in (dimensions, engines, contact_record, ranks):
                print(case.__name__)
                case(cairn, seeds, tmp)
        except (CheckFailed, subprocess.TimeoutExpired) as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print("ok: every mismatch of dimension and engine, and a bad contact record, is exit 2 naming it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
