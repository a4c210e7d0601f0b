"""Result objects: what an analysis returns. Each is a `Result` (gyro/results/_io.py: the
contract) that turns into the command line's JSON (the keys of the contract) and text,
saves and loads itself, pickles (plain dataclasses of arrays) and plots itself (or says
why it has no figure); a batch's concatenates. Results are leaves: they import no
analysis. One module per kind of result; every name is importable from `gyro.results`.

- `spectrum`: `Spectrum` (a frequency method over a batch), `Stability` and `classify`,
  `ModalResult` (one set's frequencies with its equilibrium), `nearest_error`;
- `campbell`: `CampbellDiagram` (frequencies against spin, formulas overlaid) and its
  `Crossing`s (critical speeds);
- `map`: `Map`, one quantity over a grid of two parameters, of three kinds: `verdict` (the
  stability of the equilibrium), `condition` (any model's declared sufficient condition
  against its spectrum), `error` (one level's error against a more exact one);
- `motion`: `Motion`, named series in time (any model's motion from its reference,
  gyro/analyses/motion.py, and the motions models declare of their own), what is the
  producer's (names, units, descriptions, the document's keys) given as data;
- `sweep`: `FrequencySweep` (frequencies against any one parameter);
- `conditions`: `EquilibriumStability` (any model's declared conditions against its
  spectrum at one set);
- `verdict`: `Verdict`, the one verdict type (stable, marginal, unstable, boundary,
  unknown, failed, each with its reason) and the two tests every analysis reads it through;
- `sensitivity`: `Sensitivities` (d omega / d p of every frequency and parameter);
- `tolerance`: `ToleranceStudy` (frequency distributions over manufacturing spreads);
- `scene`: `Scene` and `Trial` (a question answered at a tolerance by the cheapest adequate
  level);
- `harmonic`: `HarmonicResponse` (steady response to harmonic inputs, a Bode curve, an
  unbalance response), `ForcedResponse` (the bearing imperfections' harmonics, kept apart);
- `_io`: atomic saving of arrays and figures, shared by all.
"""
from __future__ import annotations

from gyro.results._io import TMP_TAG, Result, save_figure
from gyro.results.campbell import FORMULA_BAD, CampbellDiagram, Crossing
from gyro.results.conditions import EquilibriumStability
from gyro.results.harmonic import ForcedResponse, HarmonicResponse
from gyro.results.map import Map
from gyro.results.motion import Motion
from gyro.results.spectrum import ModalResult, Spectrum, Stability, classify, nearest_error
from gyro.results.scene import Scene, Trial
from gyro.results.sensitivity import Sensitivities
from gyro.results.sweep import FrequencySweep
from gyro.results.tolerance import ToleranceStudy
from gyro.results.verdict import Verdict

__all__ = ["TMP_TAG", "Result", "save_figure", "FORMULA_BAD", "CampbellDiagram", "Crossing", "EquilibriumStability", "ModalResult",
           "Spectrum", "Stability", "classify", "nearest_error", "Map", "FrequencySweep", "Motion", "Verdict",
           "Sensitivities", "ToleranceStudy", "Scene", "Trial", "HarmonicResponse", "ForcedResponse"]
