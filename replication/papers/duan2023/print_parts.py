"""Printed parts of duan2023 read against each other, and the quantities the print leaves out.

:func:`print_parts_rows` turns the transcription ``data/paper/duan2023/duan2023-print-parts.csv``
into comparison rows for :func:`replication.registry.exports.compare`: each vector's label
against the components it lists (§1 after eq. (1), §2 before eq. (2)); the units of the two sides
of the §3 over-correction condition; and the attitude correction of eq. (22) against the turn of
eq. (5) in the misalignment convention that the forcing of eq. (1) fixes.  Each row names its
basis; every ``agrees`` is computed here from the transcribed text.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from replication.nav import rotations
from replication.papers.duan2023 import printed

#: the vectors whose printed label is read against their bracketed symbols (quantity stem, suffix)
LABELLED = (
    ("phi", " (eq. (1))"),
    ("dp", " (eq. (1))"),
    ("dp^c", ""),
    ("S", ""),
    ("V", ""),
    ("dV^c", ""),
)

#: units of the symbols of the §3 condition (S: the horizontal displacement of eqs. (2)-(5))
UNIT = {"S": "m"}


def _unit_of(sym: str) -> str:
    """The unit of a printed symbol of the §3 condition: ``S`` or its derivative ``\\dot{S}``."""
    if sym.startswith(r"\dot{"):
        return UNIT[sym[len(r"\dot{") : -1]] + "/s"
    return UNIT[sym]


def print_parts_rows(parts: pd.DataFrame) -> list[dict]:
    """The comparison rows of ``duan2023-print-parts``.

    Parameters
    ----------
    parts : pandas.DataFrame
        ``data/paper/duan2023/duan2023-print-parts.csv`` (quantity, unit, value, line), as
        :func:`replication.registry.reproduction.load_paper` returns it in ``.data``.

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`, each with ``basis`` and a
        computed ``agrees``.

    Raises
    ------
    ValueError
        When a transcribed quantity the rows read is missing.
    """
    if not isinstance(parts, pd.DataFrame) or "quantity" not in parts.columns:
        raise ValueError(
            "parts must be the transcription DataFrame with a 'quantity' column"
            " (rp.load_paper('duan2023-print-parts').data)"
        )
    need = {"over-correction condition"}
    missing = sorted(need - set(parts["quantity"]))
    if missing:
        raise ValueError(f"the transcription lacks {missing}; add them to duan2023-print-parts.csv")
    pp = parts.set_index("quantity")
    rows = printed.label_rows(
        parts,
        [(f"{v} label{s}", f"{v} symbols{s}") for v, s in LABELLED],
    )

    # §3: "the approximate terms too large, i.e. Ṡ ≫ S" -- the units of the two sides of the
    # printed inequality
    cond = pp.loc["over-correction condition", "value"]
    lhs, rhs = (s.strip(" $") for s in cond.split("$")[1].split(r"\gg"))
    rows.append(
        dict(
            quantity="over-correction condition: units of the two sides",
            unit="",
            paper_text=cond,
            reproduced=f"{_unit_of(lhs)} against {_unit_of(rhs)}",
            basis="parts",
            agrees=_unit_of(lhs) == _unit_of(rhs),
            note=(
                "the sentence bounds the size of the approximate terms such as -Ṡ/S (a"
                " rate, 1/s); its inequality compares a speed with a displacement. Read as"
                " SI numbers it is |Ṡ/S| ≫ 1 s⁻¹, a definite rate the text does not give"
                " and 20-50 times the thresholds 1.2/T-2.5/T (T = 30 s) of the readings"
                " ledger: the sentence and its inequality disagree (line"
                f" {pp.loc['over-correction condition', 'line']})"
            ),
        )
    )
    rows.append(_eq22_sign_row())
    return rows


def _eq22_sign_row() -> dict:
    """eq. (22) adds φ^c to the misalignment; eq. (5) turns the SINS computed vectors by +φ^c
    about u; eq. (1)'s forcing -C_b^n δω fixes Ĉ = exp(-φ×) C.  Turning the computed attitude
    with the vectors gives φ_S/A."""
    phi = np.array([2e-4, -1e-4, 3e-4])  # a misalignment (rad)
    # φ^c u, u horizontal and across the track (eq. (5))
    phic_u = 1e-4 * np.array([0.6, -0.8, 0.0])
    C = rotations.rotvec_to_dcm(np.array([0.1, -0.2, 0.7]))
    C_hat = rotations.rotvec_to_dcm(-phi) @ C
    phi_sa = -rotations.dcm_to_rotvec(rotations.rotvec_to_dcm(phic_u) @ C_hat @ C.T)
    # second-order terms, stated before comparing
    SECOND = 10 * np.linalg.norm(phi) * np.linalg.norm(phic_u)
    turned = phi_sa - phi
    return dict(
        quantity=(
            "eq. (22) misalignment correction against eq. (5) in the convention of"
            " eq. (1)"
        ),
        unit="rad",
        paper_text=(
            "eq. (22): φ_S/A = φ + φ^c u; eq. (5): the computed vectors turned by +φ^c"
            " about u; eq. (1): forcing -C_b^n δω_ib^b"
        ),
        reproduced=(
            f"φ_S/A - φ = {'+' if np.allclose(turned, phic_u, atol=SECOND) else '-'}φ^c"
            f" u (first order, |residual| {np.linalg.norm(turned + phic_u):.0e})"
        ),
        basis="parts",
        agrees=bool(np.allclose(turned, phic_u, atol=SECOND)),
        note=(
            "with the convention Ĉ = exp(-φ×)C that the forcing of eq. (1) fixes,"
            " turning the computed attitude with the vectors as eq. (5) turns them"
            " subtracts φ^c u from the misalignment; eq. (22) adds it. The main run"
            " follows eq. (22) as printed, and the readings ledger of Table 1 runs the"
            " other sign too (no reading reaches the print)"
        ),
    )
