"""The extension module under the package `mbd` (Rust, PyO3). Plain data in and out; use the
typed API of `mbd` instead."""

from typing import Any, Dict, List, Optional, Tuple

__version__: str

def check(name: str, text: str, sets: List[str], lint: bool = True) -> Tuple[bool, str, Dict[str, Any]]: ...
def run(name: str, text: str, sets: List[str], solve: Optional[Dict[str, Any]] = None) -> Dict[str, Any]: ...
def modes(
    name: str,
    text: str,
    sets: List[str],
    frozen: bool = False,
    count: Optional[int] = None,
    solve: Optional[Dict[str, Any]] = None,
) -> Tuple[bool, str, str]: ...
def stability(
    name: str, text: str, sets: List[str], param: str, values: List[float], options: Dict[str, Any]
) -> Tuple[bool, str, Dict[str, Any]]: ...
def stability_share(
    name: str,
    text: str,
    sets: List[str],
    param: str,
    values: List[float],
    options: Dict[str, Any],
    k: int,
    n: int,
) -> Tuple[bool, str]: ...
def merge(shares: List[str]) -> Tuple[str, Dict[str, Any]]: ...
def grid(start: float, stop: float, step: float) -> List[float]: ...
def study(name: str, text: str, sets: List[str], args: Dict[str, Any]) -> Tuple[bool, str]: ...
