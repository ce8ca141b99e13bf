"""The report page: HTML text, tables and figures. The figures' JSON (plotly's, numpy arrays as
typed arrays) goes into one gzip-compressed, base64 block and plotly.js into another; a small
script inflates both in the browser (``DecompressionStream``, no network), draws every figure
and records in ``<body data-*>`` how many rendered, any script errors and the time to render
(used by the test in headless Chromium and benchmarks/bench_report.py)."""

from __future__ import annotations

import base64
import functools
import gzip
import html
import json

import numpy as np


class Page:
    """The parts of a report page in order; ``figures`` the plotly figures (as dicts)."""

    def __init__(self):
        self.parts: list[str] = []
        self.figures: list[dict] = []

    def add(self, text: str) -> None:
        self.parts.append(text)

    def h(self, level: int, text: str, anchor: str | None = None) -> None:
        a = f' id="{html.escape(anchor)}"' if anchor else ""
        self.add(f"<h{level}{a}>{html.escape(text)}</h{level}>")

    def plot(self, fig, alt: str) -> None:
        """A matplotlib figure, drawn interactively (plotly) from the same artists."""
        from cablelife.report.mpl_plotly import to_plotly

        self.plotly(to_plotly(fig), alt)

    def plotly(self, fig, alt: str = "") -> None:
        """A plotly figure (a ``go.Figure`` or its dict), drawn in a div of its own."""
        from cablelife.report.decimate import compact

        d = fig if isinstance(fig, dict) else fig.to_dict()
        for trace in d["data"] + [t for f in d.get("frames", []) for t in f["data"]]:
            _pack_tube(trace)
        self.figures.append(compact(d))
        label = f' aria-label="{html.escape(alt)}"' if alt else ""
        n = len(self.figures)
        height = int(d.get("layout", {}).get("height") or 450)  # plotly's default
        self.add(
            f'<div class="figure"{label}><div id="figure-{n}" class="plot" '
            f'style="height:{height}px"></div></div>'
        )

    def table(self, header: list[str], rows: list[list], caption: str = "", cls: str = "") -> None:
        cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
        body = "".join(
            "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows
        )
        c = f' class="{cls}"' if cls else ""
        self.add(f"<table{c}>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def note(self, text: str, cls: str = "note") -> None:
        self.add(f'<p class="{cls}">{html.escape(text)}</p>')

    def html(self, title: str, css: str) -> str:
        """The whole page."""
        from plotly.io.json import to_json_plotly

        payload = _pack(to_json_plotly(self.figures).encode())
        return (
            '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{html.escape(title)}</title><style>{css}</style>{CHECK_HEAD}</head>"
            f'<body data-expected-figures="{len(self.figures)}">\n'
            + "\n".join(self.parts)
            + f'\n<script type="application/gzip;base64" id="plotlyjs">{plotly_js_packed()}'
            f'</script>\n<script type="application/gzip;base64" id="figures">{payload}</script>'
            f"\n{LOADER}</body></html>\n"
        )


def _f32(a) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f4").tobytes()).decode()


def _pack_tube(trace: dict) -> None:
    """A tube mesh (``meta = {"tube": G, "radius": r}``: rings of G vertices at angles 2πk/G
    around the nodes, :func:`cablelife.report.tube.tube_mesh`) sent as its nodes and ring
    directors d1, d2 (and the values per node when they are constant around each ring): a
    third of the vertices' size; the page rebuilds the vertices (``_tube``, see LOADER)."""
    meta = trace.get("meta")
    if trace.get("type") != "mesh3d" or not isinstance(meta, dict) or "tube" not in meta:
        return
    from cablelife.report.decimate import typed

    g, r = int(meta["tube"]), float(meta["radius"])
    v = np.stack([np.asarray(typed(trace.pop(k)), float) for k in "xyz"], -1).reshape(-1, g, 3)
    c = v.mean(axis=1)
    th = 2 * np.pi / g
    d1 = (v[:, 0] - c) / r
    d2 = (v[:, 1] - c - r * np.cos(th) * d1) / (r * np.sin(th))
    tube = {"g": g, "r": r, "c": _f32(c), "d1": _f32(d1), "d2": _f32(d2)}
    if "intensity" in trace:
        w = np.asarray(typed(trace["intensity"]), float).reshape(-1, g)
        if np.all(w == w[:, :1]):
            del trace["intensity"]
            tube["v"] = _f32(w[:, 0])
    trace["_tube"] = tube


def _pack(data: bytes, level: int = 6) -> str:
    return base64.b64encode(gzip.compress(data, level, mtime=0)).decode()


@functools.cache
def plotly_js_packed() -> str:
    """plotly.js of the installed plotly, gzip-compressed (level 6: level 9 is 0.2 % smaller and
    takes a third longer) and base64 (4.8 → 2.0 MB)."""
    from plotly.offline import get_plotlyjs

    return _pack(get_plotlyjs().encode(), 6)


def unpack(page: str, block: str = "figures"):
    """The figures (a list of dicts) or plotly.js (text) of a report page: for tests."""
    import re

    m = re.search(rf'<script type="application/gzip;base64" id="{block}">([^<]*)</script>', page)
    if m is None:
        raise ValueError(f"the page has no {block!r} block")
    text = gzip.decompress(base64.b64decode(m[1])).decode()
    return json.loads(text) if block == "figures" else text


# Records script errors before anything else runs.
CHECK_HEAD = """<script>
window.__errors=[];window.addEventListener('error',function(e){__errors.push(String(e.message))});
(function(){var ce=console.error;console.error=function(){
__errors.push(Array.prototype.join.call(arguments,' '));ce.apply(console,arguments)}})();
</script>"""

# Inflates plotly.js and the figures, then draws the figures lazily, one at a time: those on
# the first screen at once, every other one when it comes near the viewport (an
# IntersectionObserver), so the page is readable in a second or two and a 3D scene (WebGL, slow
# without a GPU) costs only when looked at. Records the outcome in <body data-*>:
# data-render-ms (since navigation start, first screen drawn), data-first-screen-figures (ids),
# data-rendered-figures (so far), data-errors, data-checked = yes (first screen done); each
# figure's div gets data-state (rendered/failed) and data-ms (its drawing time). 3D scenes
# are drawn at the screen's pixel ratio (plotly's default, 2, draws four times the pixels on
# an ordinary screen: about a tenth of the page's CPU time without a GPU).
LOADER = """<script>
(async function(){
var b=document.body.dataset,figs,queue=Promise.resolve(),first=[];
async function inflate(id){
 var s=document.getElementById(id).textContent,st;
 try{st=(await fetch('data:application/octet-stream;base64,'+s)).body}
 catch(e){var bin=atob(s),a=new Uint8Array(bin.length);
  for(var i=0;i<bin.length;i++)a[i]=bin.charCodeAt(i);st=new Blob([a]).stream()}
 return await new Response(st.pipeThrough(new DecompressionStream('gzip'))).text();}
function f32(s){var bin=atob(s),a=new Uint8Array(bin.length);
 for(var i=0;i<bin.length;i++)a[i]=bin.charCodeAt(i);return new Float32Array(a.buffer);}
function tube(t){var T=t._tube;if(!T)return;delete t._tube;
 var c=f32(T.c),d1=f32(T.d1),d2=f32(T.d2),g=T.g,r=T.r,n=c.length/3,N=n*g;
 var x=new Float32Array(N),y=new Float32Array(N),z=new Float32Array(N),co=[],si=[];
 for(var k=0;k<g;k++){co.push(r*Math.cos(2*Math.PI*k/g));si.push(r*Math.sin(2*Math.PI*k/g));}
 for(var i=0;i<n;i++)for(k=0;k<g;k++){var j=i*g+k,a=co[k],b=si[k];
  x[j]=c[3*i]+a*d1[3*i]+b*d2[3*i];y[j]=c[3*i+1]+a*d1[3*i+1]+b*d2[3*i+1];
  z[j]=c[3*i+2]+a*d1[3*i+2]+b*d2[3*i+2];}
 t.x=x;t.y=y;t.z=z;
 if(T.v){var v=f32(T.v),w=new Float32Array(N);for(j=0;j<N;j++)w[j]=v[Math.floor(j/g)];
  t.intensity=w;}}
function div(i){return document.getElementById('figure-'+(i+1))}
function record(){b.renderedFigures=document.querySelectorAll('.plot[data-state=rendered]').length;
 b.errors=JSON.stringify(window.__errors);}
var gl=Math.max(1,Math.min(2,window.devicePixelRatio||1));
function draw(i){queue=queue.then(async function(){
 var d=div(i),f=figs[i],t0=performance.now();if(d.dataset.state)return;d.dataset.state='drawing';
 try{
  f.data.forEach(tube);(f.frames||[]).forEach(function(fr){fr.data.forEach(tube)});
  await Plotly.newPlot(d,f.data,f.layout,{displaylogo:false,responsive:true,plotGlPixelRatio:gl});
  if(f.frames)await Plotly.addFrames(d,f.frames);
  var L=d._fullLayout||{},g3=L._has&&L._has('gl3d');
  d.dataset.state=d.querySelector('.main-svg')&&L.width>0&&(!g3||d.querySelector('canvas'))?
   'rendered':'failed';
 }catch(e){__errors.push(String(e&&e.stack||e));d.dataset.state='failed'}
 figs[i]=null;d.dataset.ms=Math.round(performance.now()-t0);record();});return queue;}
try{
 var js=document.createElement('script');js.text=await inflate('plotlyjs');
 document.head.appendChild(js);
 figs=JSON.parse(await inflate('figures'));
 b.inflatedMs=Math.round(performance.now());
 var io=new IntersectionObserver(function(es){es.forEach(function(e){
  if(e.isIntersecting){io.unobserve(e.target);draw(+e.target.id.slice(7)-1)}})},
  {rootMargin:'0px 0px 200px 0px'});
 for(var i=0;i<figs.length;i++){var r=div(i).getBoundingClientRect();
  if(r.top<innerHeight&&r.bottom>0)first.push(i);else io.observe(div(i));}
 await Promise.all(first.map(draw));
}catch(e){__errors.push(String(e&&e.stack||e))}
record();b.firstScreenFigures=JSON.stringify(first.map(function(i){return 'figure-'+(i+1)}));
b.renderMs=Math.round(performance.now());b.checked='yes';
})();
</script>"""
