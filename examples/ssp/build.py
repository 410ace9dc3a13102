"""Builds SSP archives (SSP 1.0, System Structure and Parameterization) from flyloop's FMUs:
one `<system>.ssp` per entry of systems.SYSTEMS, holding SystemStructure.ssd and the FMUs in
resources/. Connections are made by name (an input connects to the one output of that name in
the system; an input nothing feeds is refused unless a parameter binds it or its component
lists it in open_inputs), parameters are inline ParameterBindings of each component, typed
from its modelDescription (Real, Integer or Boolean).

Usage: .venv/bin/python examples/ssp/build.py [--fmus dist/fmu] [--out dist/ssp] [SYSTEM ...]
"""

import argparse
import sys
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import fmpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
from systems import PARAMETER_SET, SYSTEMS, Component, System  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
NS = (
    'xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
    'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
    'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"'
)


class WiringError(ValueError):
    """A system that cannot be built: the message names the FMU, the variable and the system."""


def variables(fmu: Path) -> dict[str, tuple[str, str]]:
    """Each variable of `fmu`: name -> (causality, type)."""
    md = fmpy.read_model_description(str(fmu), validate=False)
    return {v.name: (v.causality, v.type) for v in md.modelVariables}


def connections(system: System, tables: dict[str, dict]) -> list[tuple[str, str, str, str]]:
    """(from component, output, to component, input) for every input some other FMU outputs."""
    found = []
    for sink in system.components:
        for name, (causality, _) in tables[sink.name].items():
            if causality != "input":
                continue
            sources = [
                c.name
                for c in system.components
                if c is not sink and tables[c.name].get(name, ("",))[0] == "output"
            ]
            if len(sources) > 1:
                raise WiringError(
                    f"system {system.name}: input `{name}` of {sink.fmu} is an output of "
                    f"{', '.join(sources)}; wiring by name needs exactly one"
                )
            if sources:
                found.append((sources[0], name, sink.name, name))
            elif name not in sink.parameters and name not in sink.open_inputs:
                raise WiringError(
                    f"system {system.name}: input `{name}` of {sink.fmu} ({sink.name}) is fed by "
                    "no output and bound by no parameter; list it in open_inputs to keep its "
                    "start value"
                )
    return found


def parameter_xml(component: Component, table: dict[str, tuple[str, str]]) -> str:
    """The component's inline ParameterBindings, typed from its modelDescription."""
    if not component.parameters:
        return ""
    rows = []
    for name, value in component.parameters.items():
        if name not in table:
            raise WiringError(
                f"{component.fmu} has no variable `{name}` (parameter of {component.name})"
            )
        causality, kind = table[name]
        if causality not in ("parameter", "input"):
            raise WiringError(
                f"`{name}` of {component.fmu} is an {causality}, not a parameter or input"
            )
        text = {
            "Real": lambda v: repr(float(v)),
            "Integer": lambda v: str(int(v)),
            "Boolean": lambda v: "true" if v else "false",
        }
        if kind not in text:
            raise WiringError(
                f"`{name}` of {component.fmu} is a {kind}; a binding is Real, Integer or Boolean"
            )
        value = f'<ssv:{kind} value="{text[kind](value)}"/>'
        rows.append(f'                <ssv:Parameter name="{name}">{value}</ssv:Parameter>')
    body = "\n".join(rows)
    return f"""      <ssd:ParameterBindings>
        <ssd:ParameterBinding>
          <ssd:ParameterValues>
            <ssv:ParameterSet version="1.0" name="{PARAMETER_SET}">
              <ssv:Parameters>
{body}
              </ssv:Parameters>
            </ssv:ParameterSet>
          </ssd:ParameterValues>
        </ssd:ParameterBinding>
      </ssd:ParameterBindings>
"""


def ssd(system: System, tables: dict[str, dict]) -> str:
    """SystemStructure.ssd of `system`."""
    # Parameters first: a misspelt parameter is named as such, not as an unfed input.
    bindings = {c.name: parameter_xml(c, tables[c.name]) for c in system.components}
    wires = connections(system, tables)
    watched = {tuple(w.split(".", 1)) for w in system.watch}
    for component, name in watched:
        if tables.get(component, {}).get(name, ("",))[0] != "output":
            raise WiringError(
                f"system {system.name}: watched `{component}.{name}` is no output there"
            )
    elements = []
    for c in system.components:
        used = {(w[0], w[1]) for w in wires} | {(w[2], w[3]) for w in wires} | watched
        connectors = [
            f'        <ssd:Connector name="{n}" kind="{k}"><ssc:Real/></ssd:Connector>'
            for n, (k, _) in tables[c.name].items()
            if (c.name, n) in used
        ]
        elements.append(
            f'    <ssd:Component name="{c.name}" type="application/x-fmu-sharedlibrary" '
            f'source="resources/{c.fmu}">\n      <ssd:Connectors>\n'
            + "\n".join(connectors)
            + "\n      </ssd:Connectors>\n"
            + bindings[c.name]
            + "    </ssd:Component>"
        )
    lines = [
        f'      <ssd:Connection startElement="{a}" startConnector="{o}" '
        f'endElement="{b}" endConnector="{i}"/>'
        for a, o, b, i in wires
    ]
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription {NS} version="1.0" name={quoteattr(system.name)}>
  <ssd:System name={quoteattr(system.name)} description={quoteattr(system.description)}>
  <ssd:Elements>
{chr(10).join(elements)}
  </ssd:Elements>
  <ssd:Connections>
{chr(10).join(lines)}
  </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="{system.stop_time}"/>
</ssd:SystemStructureDescription>
"""


def build(system: System, fmus: Path, out: Path) -> Path:
    """Writes out/<system>.ssp; nothing is written when the system is refused."""
    for c in system.components:
        if not (fmus / c.fmu).is_file():
            raise WiringError(
                f"system {system.name}: {fmus / c.fmu} (component {c.name}) does not exist"
            )
    tables = {c.name: variables(fmus / c.fmu) for c in system.components}
    text = ssd(system, tables)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{system.name}.ssp"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", text)
        for fmu in sorted({c.fmu for c in system.components}):
            z.write(fmus / fmu, f"resources/{fmu}")
    return path


def main(argv=None) -> list[Path]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--fmus", type=Path, default=ROOT / "dist" / "fmu", help="folder of the packed FMUs"
    )
    parser.add_argument("--out", type=Path, default=ROOT / "dist" / "ssp")
    parser.add_argument(
        "systems", nargs="*", default=list(SYSTEMS), help=f"any of {', '.join(SYSTEMS)}"
    )
    args = parser.parse_args(argv)
    unknown = [s for s in args.systems if s not in SYSTEMS]
    if unknown:
        parser.error(f"unknown system {unknown[0]!r}: known are {', '.join(SYSTEMS)}")
    paths = [build(SYSTEMS[name], args.fmus, args.out) for name in args.systems]
    for path in paths:
        print(path)
    return paths


if __name__ == "__main__":
    main()
