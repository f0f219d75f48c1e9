"""Builders of expected programs (plain dicts, as Program.to_dict writes them) for the parser
corpora: corpus_dev.py and corpus_phrasing.py."""

import math


def deg(x):
    return math.radians(x)


def walk(**kw):
    return {"kind": "walk", **kw}


def turn(**kw):
    return {"kind": "turn", **kw}


def stand(d):
    return {"kind": "stand", "duration_s": float(d)}


def style(name, d=None):
    out = {"kind": "style", "name": name}
    if d is not None:
        out["duration_s"] = float(d)
    return out


def height(**kw):
    return {"kind": "height", **kw}


def reach(**kw):
    return {"kind": "reach", **kw}


def pick(obj, hands=None, **kw):
    out = {"kind": "pick", "object": obj, **kw}
    if hands:
        out["hands"] = hands
    return out


def place(obj, target=None, **kw):
    out = {"kind": "place", "object": obj, **kw}
    if target:
        out["target"] = target
    return out


def up(p, **kw):
    return {"kind": "step_up", "platform": p, **kw}


def down(p=None, **kw):
    out = {"kind": "step_down", **kw}
    if p:
        out["platform"] = p
    return out


def par(main, *alongside):
    return {"kind": "parallel", "main": main, "alongside": list(alongside)}


def rep(n, *steps):
    return {"kind": "repeat", "count": n, "steps": list(steps)}
