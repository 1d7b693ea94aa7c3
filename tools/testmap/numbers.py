"""Fixed number formatting so output bytes never depend on float repr details."""


def fmt(value):
    if isinstance(value, str):
        return value
    text = _CACHE.get(value)
    if text is None:
        text = _CACHE[value] = _fmt(value)
    return text


_CACHE = {}


def _fmt(value):
    v = round(float(value), 4)
    if v == 0:
        return "0"
    if v == int(v):
        return str(int(v))
    return ("%.4f" % v).rstrip("0").rstrip(".")


def fmt_vec(values):
    cache = _CACHE
    try:
        return " ".join([cache[v] for v in values])
    except (KeyError, TypeError):
        return " ".join([fmt(v) for v in values])
