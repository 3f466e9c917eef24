"""The case families' expression functions.  Importing this package registers all of them in
harness/expressions.py: each module registers its own when it is imported.

    signals      period, settle, sine_period, sine_amplitude: one series as a signal
    variants     series, of, order: another variant of the same case
    piles        pile_X, pile_S, middle, horizontal_contacts, weight: a pile's stress (MLH 2000)
    networks     contact_error, contact_mismatch: contact forces against another variant's
    collisions   contact_start, contact_end, contact_duration, restitution: a binary collision
    rolling      fit_slope: a straight line through a branch of a curve (the rolling law tester)
    biaxial      sigma_v, phi, axial_strain, phi_peak, phi_residual, phi_envelope, ...: a biaxial
                 compression test and its strength envelope (JYH 2005)
    ensembles    members, seeds, realisations, over: the realisations of an [ensemble]
    pile_stats   ens_S, dip, dip_se, coordination, ens_forces, tail_rate, ...: polydisperse
                 piles over an [ensemble] (MLH 2000, Sec. 4.4)
    coulomb      coulomb_error, sliding_contacts: the Coulomb cap at the sliding contacts of
                 a final state (C&S eq. 19)

A new family is one module here that calls expressions.register, and its name below.  The
order of the imports is the order in which an unknown-function message lists the names.
"""
from . import signals  # noqa: F401 -- each import registers the module's functions
from . import variants  # noqa: F401
from . import piles  # noqa: F401
from . import networks  # noqa: F401
from . import collisions  # noqa: F401
from . import rolling  # noqa: F401
from . import biaxial  # noqa: F401
from . import ensembles  # noqa: F401
from . import pile_stats  # noqa: F401
from . import coulomb  # noqa: F401
