"""Export the model: MJCF, URDF and C

The mechanism written for other tools from one parameter set: MJCF for MuJoCo (the real topology, both links of each
parallelogram, the mass model, the loop closures as `<equality><connect>`), URDF (mimic joints; the remaining leg
closure is documented in the file) and the closed form as C99 for a motion controller (`tpm_2ppa.h`, `tpm_2ppa.c`:
inverse kinematics, Jacobian, inverse and forward dynamics, the computed-torque law; `libm` only). The same as
`tpm-viz export --format mjcf|urdf|c`. `examples/ctc_loop.c` runs the C in a 1 kHz loop
([the examples](../index.md#the-generated-c-in-a-1-khz-loop), [realtime.md](../../realtime.md)).
"""

import pathlib
import xml.etree.ElementTree as ET

from tpm_viz import Params
from tpm_viz.exchange import mjcf_text, urdf_text
from tpm_viz.exchange.c.code import c_files

params = Params.paper(m_p=3.1)  # your machine's parameters (SI); the files carry them

pathlib.Path("tpm_2ppa.xml").write_text(mjcf_text(params))
pathlib.Path("tpm_2ppa.urdf").write_text(urdf_text(params))
for name in ("tpm_2ppa.xml", "tpm_2ppa.urdf"):
    root = ET.parse(name).getroot()  # well-formed XML
    print(f"wrote {name}: <{root.tag}> with {len(root.findall('.//joint'))} joints")

gen = pathlib.Path("gen")
gen.mkdir(exist_ok=True)
for name, text in c_files(params).items():
    (gen / name).write_text(text)
    print(f"wrote gen/{name} ({len(text.splitlines())} lines)")
print("compile: cc -std=c99 -O2 -Wall -Wextra -pedantic -I gen examples/ctc_loop.c gen/tpm_2ppa.c -o ctc_loop -lm")
