"""harness/peer: ballast against LAMMPS on the same physics.

Modules, each run from the repository root with /usr/bin/python3 -m:

    harness.peer.check    the cross-check (the catalogue's case peer_check)
    harness.peer.rolling  JYH's rolling resistance against LAMMPS's pair granular
                          (the case peer_rolling)
    harness.peer.race     `make bench-peer`: the cross-check, then the race

and harness.peer.common, what they share: the two programs (Codes, given as --ballast
and --lmp), the inputs written for both codes, the outputs read back, the comparison,
installing LAMMPS.  in.peer and in.peer_rolling are the LAMMPS inputs they fill in.
"""
