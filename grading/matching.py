"""Matching a function's answers with the known mistakes of its catalogue.

A catalogue entry (:mod:`grading.instructors.mistakes`) gives a function's
``truth`` and its ``mistakes``, each predicting what it would answer on the
same inputs. :func:`best_mistake` compares every mistake's predictions with
the submission's answers, call by call (:func:`_verdict`), and names the
mistake that explains the most failed tests: step 4 of
:mod:`grading.diagnosis`, which builds the diagnosis from it.
"""

import copy
import hashlib
import os
import sys
from dataclasses import dataclass

import numpy as np

__all__ = ["RANDOM", "CHANCE_LIMIT", "Raised", "Variants", "same", "best_mistake"]


def same(a, b, rtol=1e-6, atol=1e-8):
    """Whether two answers are equal: arrays (NaN equal to NaN), numbers, tuples, dicts."""
    if isinstance(a, tuple) or isinstance(b, tuple):
        return (
            isinstance(a, tuple)
            and isinstance(b, tuple)
            and len(a) == len(b)
            and all(same(x, y, rtol, atol) for x, y in zip(a, b))
        )
    if isinstance(a, dict) or isinstance(b, dict):
        return (
            isinstance(a, dict)
            and isinstance(b, dict)
            and set(a) == set(b)
            and all(same(a[k], b[k], rtol, atol) for k in a)
        )
    try:
        a, b = np.asarray(a), np.asarray(b)
    except Exception:
        return False
    if a.shape != b.shape:
        return False
    if a.dtype.kind in "biu" and b.dtype.kind in "biu":
        return bool(np.array_equal(a, b))
    try:
        return bool(np.allclose(a.astype(float), b.astype(float), rtol=rtol, atol=atol, equal_nan=True))
    except (TypeError, ValueError):
        return False


RANDOM = object()  # a truth that cannot be predicted (a random method): any mistake that applies differs


@dataclass(frozen=True)
class Raised:
    """An answer that is an exception (its type's name): what a call raised, or what a mistake raises."""

    error_type: str


class Variants(tuple):
    """Several answers a mistake may give (ways of writing it that round differently)."""


CHANCE_LIMIT = 1e-3  # a test whose answers a right random method gives this often is no evidence


def _fingerprint(arguments):
    """A digest of a call's arguments (arrays by content, generators by state): 32 bytes, whatever
    the arguments' size, as a verdict keeps it for the rest of the grading."""
    digest = hashlib.blake2b(digest_size=32)
    for name, value in sorted(arguments.items()):
        if isinstance(value, np.ndarray):
            digest.update(repr((name, value.shape, value.dtype.str)).encode())
            digest.update(value.tobytes())
        elif isinstance(value, np.random.Generator):
            digest.update(repr((name, value.bit_generator.state)).encode())
        else:
            digest.update(repr((name, value)).encode())
    return digest.digest()


def _chance(predicted):
    """The chance that a right answer equals this prediction (0 for a deterministic function's)."""
    if isinstance(predicted, Variants):
        return max((_chance(p) for p in predicted), default=0.0)
    chance = getattr(predicted, "chance", None)
    return float(chance()) if callable(chance) else 0.0


def _matches(compare, answer, predicted, arguments):
    if isinstance(predicted, Variants):
        return any(_matches(compare, answer, p, arguments) for p in predicted)
    if isinstance(answer, Raised) or isinstance(predicted, Raised):
        return (
            isinstance(answer, Raised) and isinstance(predicted, Raised) and answer.error_type == predicted.error_type
        )
    return compare(answer, predicted, arguments)


def _debug(function, mistake, why, test):
    if os.environ.get("PCL_DIAGNOSIS_DEBUG"):
        print(f"diagnosis of {function}: not {mistake}: {why} in {test}", file=sys.stderr)


def _wrong(call, truth, model, arguments):
    """Whether a call on an input the contract accepts answered wrong: an exception, or not the truth."""
    return call.raised or not model.same(call.result, truth, arguments)


# What one call says of one mistake (:func:`_verdict`), in the order of the checks.
NO_EVIDENCE, REJECTS, WRONG_WHERE_RIGHT, MATCHED, ABSENT, OWN_CHECK, CONTRADICTED = range(7)


def _verdict(model, mistake, call, arguments, truth):
    """What ``call`` says of ``mistake``: ``(kind, detail)``, ``kind`` one of the constants above;
    ``detail`` is ``(fingerprint of the arguments, chance)`` for MATCHED, None otherwise."""
    compare = mistake.same or model.same
    try:
        predicted = mistake.predict(**copy.deepcopy(arguments))
    except Exception:
        predicted = None
    applies = predicted is not None  # None: the mistake does not apply to this input
    if isinstance(predicted, Variants) and truth is not RANDOM:
        # Only the ways of making the mistake that change the answer are evidence.
        predicted = Variants(v for v in predicted if not _matches(compare, truth, v, arguments)) or None
    if predicted is None or (truth is not RANDOM and _matches(compare, truth, predicted, arguments)):
        # The mistake gives the right answer here, or does not apply: no evidence, unless
        # the mistake is exclusive (then the answer must be right here).
        if truth is not RANDOM and _wrong(call, truth, model, arguments):
            if getattr(mistake, "exclusive", False):
                return REJECTS, None
            if applies:
                return WRONG_WHERE_RIGHT, None
        return NO_EVIDENCE, None
    answer = Raised(call.error_type) if call.raised else call.result
    if _matches(compare, answer, predicted, arguments):
        return MATCHED, (_fingerprint(arguments), _chance(predicted))
    if (
        truth is not RANDOM
        and not call.raised
        and _chance(predicted) == 0.0  # a random method's mismatch is evidence against
        and model.same(call.result, truth, arguments)
    ):
        return ABSENT, None  # the answer is right here: the mistake is not on this code path
    if call.raised and call.error_type == "ValueError":
        return OWN_CHECK, None  # a check of the student's own that the model lacks: no evidence either way
    return CONTRADICTED, None


def _truth(model, arguments):
    """The call's right answer, or None on an input the contract rejects (nothing to compare)."""
    try:
        return model.truth(**copy.deepcopy(arguments))
    except Exception:
        return None


def _is_right(model, call, arguments, truth):
    """Whether the call answered the one right answer: never for a random truth, or for a model whose
    right answers are many (``Model.unique_truth`` False: a set of acceptable draws)."""
    if not getattr(model, "unique_truth", True) or truth is None or truth is RANDOM:
        return False
    return not _wrong(call, truth, model, arguments)


def _deferred(mistake, right):
    """Whether a (mistake, call) verdict waits until a tie needs it: a right answer of a unique truth,
    compared by the model's ``same``, is ABSENT or NO_EVIDENCE for every deterministic mistake (a
    prediction that differs from the truth differs from the answer), so it is no evidence for or
    against and only breaks a tie (:func:`best_mistake`). A mistake with its own ``same`` may compare
    more loosely: its verdicts on right answers are taken at once."""
    return right and mistake.same is None


def _verdicts(model, kept, memo, mistakes, deferred=False):
    """``{(id(mistake), id(call)): verdict}`` for ``mistakes`` and the kept calls (``(call,
    arguments)``), computed once per pair: ``memo`` keeps them for another diagnosis of the same calls
    (a grading diagnoses the public tests' calls, then all of them), and whether each call answered
    right (``("right", id(call))``). ``deferred``: the pairs :func:`_deferred` left, else the others.
    The truth of a call is computed only for a call with a verdict to find."""
    for call, arguments in kept:
        truth = None
        if ("right", id(call)) not in memo:  # the first diagnosis of this call: its truth decides
            truth = _truth(model, arguments)
            memo["right", id(call)] = _is_right(model, call, arguments, truth)
        right = memo["right", id(call)]
        wanted = [m for m in mistakes if (id(m), id(call)) not in memo and _deferred(m, right) == deferred]
        if not wanted:
            continue
        if truth is None:  # computed again only for a call with a verdict still to find
            truth = _truth(model, arguments)
        for mistake in wanted:
            if truth is None:
                memo[id(mistake), id(call)] = (NO_EVIDENCE, None)
            else:
                memo[id(mistake), id(call)] = _verdict(model, mistake, call, arguments, truth)
    return memo


def _tally(function, mistake, kept, verdicts, failed):
    """What the verdicts of ``mistake`` say, over every call: ``(explained, contradicted, unexplained,
    absent, evidence)``, or None where the mistake is rejected (wrong where it gives the right answer,
    for an exclusive mistake). A pair not in ``verdicts`` (deferred) counts as no evidence."""
    matched, contradicted, luck, seen = set(), set(), {}, {}
    wrong_where_right = set()  # tests with a wrong answer where the mistake gives the right one
    evidence, absent = 0, 0  # calls the mistake predicts; calls where it differs and the answer is right
    for call, _ in kept:
        kind, detail = verdicts.get((id(mistake), id(call)), (NO_EVIDENCE, None))
        if kind == REJECTS:
            _debug(function, mistake.id, "wrong where the mistake is right", call.test)
            return None
        if kind == WRONG_WHERE_RIGHT:
            wrong_where_right.add(call.test)
        elif kind == MATCHED:
            matched.add(call.test)
            evidence += 1
            # A random method's right answer may equal the mistake's by chance: a test is
            # evidence only when that chance, over all of its calls, is small.
            # Calls with the same arguments (the same seed) are one draw, not several.
            key, chance = detail
            if key not in seen.setdefault(call.test, set()):
                seen[call.test].add(key)
                luck[call.test] = luck.get(call.test, 1.0) * chance
        elif kind == ABSENT:
            absent += 1
        elif kind == CONTRADICTED:
            _debug(function, mistake.id, "does not match its prediction", call.test)
            contradicted.add(call.test)
    # A test is explained when the mistake predicts its answers and nothing contradicts it there.
    explained = tuple(t for t in failed if t in matched and t not in contradicted and luck.get(t, 0.0) < CHANCE_LIMIT)
    unexplained = [t for t in failed if t in wrong_where_right and t not in matched and t not in contradicted]
    return explained, contradicted, unexplained, absent, evidence


def best_mistake(function, model, kept, failed, memo):
    """The mistake of ``model`` that explains the most of the ``failed`` tests, with those tests:
    ``(mistake, explained)``, or None.

    ``kept`` is the function's recorded calls with their bound arguments
    (``(call, arguments)``); ``memo`` keeps the verdicts for another
    diagnosis of the same calls (:func:`_verdicts`). A mistake is named when
    it explains more tests than contradict it, and at least as many as fail
    where it would have answered right (the code then has another fault:
    naming this one would send the student after a mistake the failures do
    not show). The most explained, then the fewest contradicting, win; a tie
    goes to the mistake that differs from fewer right answers, then to the
    one with more matched calls: those right answers' verdicts are computed
    for the tied mistakes only (:func:`_deferred`), as most of a grading's
    calls are right and each verdict replays the mistake.
    """
    verdicts = _verdicts(model, kept, memo, model.mistakes)
    candidates = []
    for mistake in model.mistakes:
        tally = _tally(function, mistake, kept, verdicts, failed)
        if tally is None:
            continue
        explained, contradicted, unexplained = tally[:3]
        _debug(
            function,
            mistake.id,
            f"explains {len(explained)}, contradicted by {len(contradicted)}, "
            f"wrong where it is right in {len(unexplained)}",
            "all",
        )
        if explained and len(explained) > len(contradicted) and len(explained) >= len(unexplained):
            candidates.append((mistake, (len(explained), -len(contradicted))))
    if not candidates:
        return None
    top = max(key for _, key in candidates)
    tied = [mistake for mistake, key in candidates if key == top]
    if len(tied) > 1:
        verdicts = _verdicts(model, kept, memo, tied, deferred=True)
    best, best_key = None, None
    for mistake in tied:
        tally = _tally(function, mistake, kept, verdicts, failed)
        if tally is None:
            continue
        explained, contradicted, _, absent, evidence = tally
        key = (len(explained), -len(contradicted), -absent, evidence)
        if best_key is None or key > best_key:
            best, best_key = (mistake, explained), key
    return best
