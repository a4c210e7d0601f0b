"""The selector: a question answered at a tolerance by the cheapest level of the model's
hierarchy whose bound meets it for every requested quantity (docs/hierarchy.md).

A loop over the declared levels, cheapest first. For each level and the sets still
unanswered: the a-priori part of its bound (emitted, evaluated per set) and its edges of
validity decide, before the level is run, whether it can be enough; the level then runs
on those sets only, and its answer is taken where the whole bound (a-priori part plus
the evaluator's own estimate), the question's edges (veering, no verdict) and the answer
itself (computed, finite) hold. The other sets go on up the hierarchy. Nothing here
knows a model or a question by name; the error of one level against another (an error
map's entry) is `level_error`.
"""
from __future__ import annotations

import time

import numpy as np

from gyro import levels as hierarchy
from gyro import questions
from gyro.ladder import as_batch
from gyro.results import Scene
from gyro.results.scene import (ACCEPTED, APRIORI, BOUND, EDGE, FAILED, NOT_ANSWERED, QUESTION_EDGE,
                                Trial)


def select(model, question: str, P, tol: float, opts: dict | None = None, among: list | None = None) -> Scene:
    """Answer `question` for every set of P (sets, parameters) within the relative `tol`.

    `opts` are the question's options (`modes` for frequencies, `horizon` for motion);
    `among` restricts the hierarchy to these level names. Sets that no level can answer
    keep level '' and the smallest bound offered (`Scene.best`)."""
    if not (np.isfinite(tol) and 0 < tol < 1):
        raise ValueError(f"--tol: must be a finite number in (0, 1), got {tol!r}")
    t0 = time.perf_counter()
    opts = dict(opts or {})
    opts.setdefault("tol", tol)
    q = questions.get(question)
    P = as_batch(model, P)
    names = q.quantities(model, opts)
    idx = q.requested(model, opts)
    N, nq = P.shape[0], len(names)
    cands = candidates(model, q, question, idx, among)
    if not cands:
        from gyro.errors import ParameterError

        raise ParameterError(f"question {question!r}: {model.name} declares no level that answers it")
    level = np.full(N, "", object)
    bound = np.full((N, len(idx)), np.inf)
    row = np.full(N, -1)
    trials, answers = [], {}
    pending = np.arange(N)
    # what the certificates of the levels a set tries share (the exact operator: made once a set)
    shared = q.certificate_data(model, P) if hasattr(q, "certificate_data") else None
    for lv in cands:
        if pending.size == 0:
            break
        trial = Trial(lv.name, np.zeros(N, np.int8), np.full(N, np.nan), tol=tol)
        trials.append(trial)
        B = hierarchy.bounds(model, lv, question, P[pending], nq)
        missing = [names[j] for j in idx if not B.answered[j]]
        if missing:  # the level does not answer a requested quantity: no set can take it
            trial.code[pending], trial.missing = NOT_ANSWERED, ", ".join(missing)
            continue
        pre = B.apriori[:, idx].max(axis=1) if idx else np.zeros(pending.size)
        beyond = B.bad
        # a level with a certificate may prove the tolerance itself where its own bound is larger
        certifying = bool(lv.evaluator.get("certify")) and hasattr(q, "certify")
        hopeful = ~beyond & ((pre <= tol) | certifying)
        trial.code[pending[beyond]] = EDGE
        if beyond.any():
            trial.say(pending[beyond], B.invalid[beyond])
        far = ~beyond & ~hopeful
        trial.code[pending[far]], trial.value[pending[far]] = APRIORI, pre[far]
        sub = np.flatnonzero(hopeful)
        if sub.size == 0:
            continue
        ks = pending[sub]
        ans = answer_per_set(q, model, lv, P[ks], q.subset(opts, ks, N) if hasattr(q, "subset") else opts)
        total = hierarchy.Bounds(B.apriori[sub], B.estimate, B.invalid[sub], B.answered, B.bad[sub]).total(ans.estimate)
        failed = ans.failed != ""
        if certifying:
            total, edge = proven(q, model, lv, P[ks], ans, total, idx, tol, question,
                                 None if shared is None else shared.take(ks))
        else:
            edge = q.edges(model, ans, total, idx, B.answered)
        worst = total[:, idx].max(axis=1) if idx else np.zeros(sub.size)
        crossed = edge != ""
        ok = ~failed & ~crossed & (worst <= tol)
        trial.value[ks] = worst
        trial.code[ks] = np.where(ok, ACCEPTED, np.where(failed, FAILED, np.where(crossed, QUESTION_EDGE, BOUND)))
        if failed.any():
            trial.say(ks[failed], ans.failed[failed])
        if (crossed & ~failed).any():
            trial.say(ks[~failed & crossed], edge[~failed & crossed])
        level[ks[ok]] = lv.name
        bound[ks[ok]] = total[ok][:, idx]
        row[ks[ok]] = np.flatnonzero(ok)
        answers[lv.name] = (q, model, ans, idx)
        pending = np.delete(pending, sub[ok])
    return Scene(model.name, question, float(tol), [names[j] for j in idx], level, bound, trials,
                 time.perf_counter() - t0, answers, row)


def proven(q, model, lv, P, ans, total, idx, tol, question: str = "frequencies", data=None):
    """The bound a level's certificate proves per set and requested quantity, and per set
    the reason where it proves none: its own bound where that is within reach, else tol
    itself (the certificate proves an interval of any width: a cheap answer whose own bound
    is pessimistic is taken where it is within tol of the exact model); where its own bound
    fails the proof, tol is tried. The certificate judges the exact model as evaluated in
    double precision; with {"certify": {"inputs": LEVEL}} the a-priori part of LEVEL's bound
    (the rounding of the inputs, u cos(phi) near the pole) separates that from the exact
    model: a proven c and an input term t make c + t + c t, so c is at most
    (tol - t)/(1 + t). inf where nothing is proven; the rank of each mode is proven with
    it, so no neighbour's interval is an edge. `data`: what the certificates of these sets
    share (the question's `certificate_data`, taken at their rows), or None."""
    spec = lv.evaluator.get("certify")
    t = np.zeros(total.shape)
    if isinstance(spec, dict) and spec.get("inputs"):
        ref = hierarchy.get(model, spec["inputs"])
        t = hierarchy.bounds(model, ref, question, P, total.shape[1]).apriori
        t = np.where(np.isfinite(t), t, np.inf)
    with np.errstate(invalid="ignore"):
        room = (tol - t) / (1 + t)
    claim = np.where(total <= room, total, room)
    reason = np.full(P.shape[0], "", object)
    short = ~np.all(room[:, idx] > 0, axis=1) if idx else np.zeros(P.shape[0], bool)
    reason[short] = "certificate: the rounding of the inputs alone exceeds the tolerance"
    live = np.flatnonzero((ans.failed == "") & ~short)
    if live.size and idx:
        part = (lambda rows: {}) if data is None else (lambda rows: {"data": data.take(rows)})  # noqa: E731
        reason[live] = q.certify(model, lv, P[live], ans.take(live), claim[live], idx, **part(live))
        again = live[(reason[live] != "") & np.any(claim[live][:, idx] < room[live][:, idx], axis=1)]
        if again.size:
            second = q.certify(model, lv, P[again], ans.take(again), room[again], idx, **part(again))
            took = again[second == ""]
            claim[took], reason[took] = room[took], ""
    out = claim + t + claim * t
    out[reason != ""] = np.inf
    return out, reason


def candidates(model, q, question: str, idx, among=None) -> list:
    """The levels that answer `question`, in the order the selector tries them: by their
    cost with their certificate's for the requested quantities (the question's
    `certificate_cost`, where it has one), ties in the declared order."""
    cost = getattr(q, "certificate_cost", lambda lv, idx: 0.0)
    found = [lv for lv in hierarchy.levels(model) if lv.answers_question(question)
             and (among is None or lv.name in among)]
    order = sorted(range(len(found)), key=lambda i: (found[i].cost + cost(found[i], idx), i))
    return [found[i] for i in order]


def answer_per_set(q, model, lv, P, opts):
    """The level's answer over the batch; where it raises for the batch, set by set, so
    that a set the level cannot answer (no equilibrium, a block without its roots, a
    singular solve) fails that set only, with the exception's text as its reason. Bad
    input (ParameterError) is the caller's, not a set's."""
    from gyro.errors import ParameterError
    from gyro.questions import Answer

    try:
        return q.answer(model, lv, P, opts)
    except ParameterError:
        raise
    except Exception as exc:  # noqa: BLE001 - any failure of a level is that level's, per set
        if P.shape[0] == 1:
            n = len(q.quantities(model, opts))
            text = (str(exc).splitlines() or [""])[0]  # one line: the reason is a table row
            return Answer(np.full((1, n), np.nan), None, np.array([f"{type(exc).__name__}: {text}"], object), {})
    N = P.shape[0]
    sub = (lambda k: q.subset(opts, np.array([k]), N)) if hasattr(q, "subset") else (lambda k: opts)
    parts = [answer_per_set(q, model, lv, P[k:k + 1], sub(k)) for k in range(N)]
    return _joined(parts)


def _joined(parts):
    """One Answer from the answers of single sets (a failed set's values NaN, its estimate
    inf and its other data NaN, shaped like an answered set's)."""
    from gyro.questions import Answer

    good = [a for a in parts if a.failed[0] == ""]
    like = good[0] if good else parts[0]
    values = np.concatenate([a.values if a.values.shape[1:] == like.values.shape[1:]
                             else np.full((1,) + like.values.shape[1:], np.nan) for a in parts])
    est = None
    if any(a.estimate is not None for a in parts):
        est = np.concatenate([a.estimate if a.estimate is not None else np.full((1,) + values.shape[1:], np.inf)
                              for a in parts])
    extra = {}
    for key, v in like.extra.items():
        fill = lambda a: (a.extra[key] if key in a.extra and a.extra[key] is not None  # noqa: E731
                          else np.full((1,) + np.shape(v)[1:], np.nan))
        extra[key] = None if v is None else np.concatenate([fill(a) for a in parts])
    return Answer(values, est, np.concatenate([a.failed for a in parts]), extra)


def level_error(model, question: str, level: str, against: str, P, opts: dict | None = None):
    """The measured relative error of `level` against the level `against` per set and
    quantity (an error map's entries), with the bound `level` declares there:
    (error, bound), each (sets, quantities); NaN error where either level failed."""
    opts = dict(opts or {})
    q = questions.get(question)
    P = as_batch(model, P)
    a, r = hierarchy.get(model, level), hierarchy.get(model, against)
    nq = len(q.quantities(model, opts))
    ans, ref = q.answer(model, a, P, opts), q.answer(model, r, P, opts)
    err = q.error(ans, ref)
    err[(ans.failed != "") | (ref.failed != "")] = np.nan
    B = hierarchy.bounds(model, a, question, P, nq)
    return err, B.total(ans.estimate)


def rungs(model, question: str, P, opts: dict | None = None, until: str | None = None) -> list:
    """The levels the selector can take for `question` on the sets P, in its order for this
    request (`candidates`): those that answer every requested quantity and are not
    dominated on P, a level being dominated where a cheaper one's largest bound over the
    requested quantities is no larger on every set. A level with a certificate is never
    dominated: it may prove the tolerance where its own bound says less. The rungs of the
    hierarchy's property tests; `until` names the last level looked at (the costlier ones
    are not run)."""
    opts = dict(opts or {})
    q = questions.get(question)
    P = as_batch(model, P)
    idx = q.requested(model, opts)
    nq = len(q.quantities(model, opts))
    out, worst = [], []
    for lv in candidates(model, q, question, idx):
        B = hierarchy.bounds(model, lv, question, P, nq)
        if not all(B.answered[j] for j in idx):
            continue
        certifying = bool(lv.evaluator.get("certify")) and hasattr(q, "certify")
        w = B.total(q.answer(model, lv, P, opts).estimate)[:, idx].max(axis=1)
        if not certifying and any(np.all(v <= w) for v in worst):
            continue
        out.append(lv.name)
        if not certifying:
            worst.append(w)
        if lv.name == until:
            break
    return out
