"""The report page's own script and style (inline in the page: the file needs no network)."""

STYLE = """
body{font:14px/1.4 system-ui,sans-serif;margin:1em auto;max-width:1100px;color:#222;padding:0 1em}
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.5em;border-bottom:1px solid #ccc}
table{border-collapse:collapse}td,th{padding:2px 10px;border-bottom:1px solid #eee;text-align:left;vertical-align:top}
.views{display:flex;gap:1em;flex-wrap:wrap}.view{border:1px solid #ccc;background:#fbfbfb}
.controls{margin:.5em 0;display:flex;gap:1em;align-items:center}
#slider{flex:1}.warn{color:#a40}.note{color:#666;font-size:.9em}
svg .body{stroke:#555;stroke-width:8}svg .leg{stroke:#555;stroke-width:4}svg .boom{stroke:#e0a000;stroke-width:7}
svg .girder{stroke:#3a6ea5;stroke-width:8}svg .rope{stroke:#333;stroke-width:1.5}svg .sling{stroke:#333;stroke-width:1}
svg .trolley{fill:#3a6ea5}svg .payload{fill:#8a5a2b}svg .hook{fill:#c00}svg .pad{fill:#777}
svg .ground{stroke:#6b4;stroke-width:2}svg .beam{stroke:#555;stroke-width:4}
svg .scalebar{stroke:#000;stroke-width:2}svg .trail{stroke-width:1}svg .trail-hook{stroke:#c00}
svg .trail-payload{stroke:#8a5a2b}svg .scalebar-text{fill:#000}svg .arrow{stroke:#080;stroke-width:2.5;fill:none}svg .anchor{fill:#555}
svg line,svg polyline,svg path{vector-effect:non-scaling-stroke}
.verdict{font-size:1.3em;padding:.4em .8em;margin:.5em 0;border-left:8px solid}
.verdict.pass{background:#e6f4ea;border-color:#1e8e3e;color:#0d5c25}.verdict.fail{background:#fce8e6;border-color:#d93025;color:#a50e0e}
tr.fail td{color:#a50e0e}tr.fail td:last-child{font-weight:bold}tr.pass td:last-child{color:#1e8e3e}.stop{color:#a50e0e}
.plot{margin:.3em 0}.plot .axis{stroke:#999}.plot .grid{stroke:#eee}.plot .cursor{stroke:#c00}
.plot .zoom{fill:rgba(0,0,200,.1)}.plot .mark{stroke:#a40;stroke-dasharray:2 2}.plot .mark-label{fill:#a40}.plot text{font-size:11px}.tip{font-size:12px;color:#333;min-height:1.4em}
"""

SCRIPT = r"""
(function(){
"use strict";
var D = JSON.parse(document.getElementById("report-data").textContent);
var NS = "http://www.w3.org/2000/svg";
var T = D.frames.t, N = T.length, frame = 0, playing = null;
function el(tag, attrs, parent){var e=document.createElementNS(NS,tag);for(var k in attrs)if(attrs[k]!==null)e.setAttribute(k,attrs[k]);if(parent)parent.appendChild(e);return e;}
function fixed(v, d){return (v===null||!isFinite(v))?"-":v.toFixed(d);}
function fmt(v){if(v===null||!isFinite(v))return "-";var a=Math.abs(v);return (a!==0&&(a<1e-3||a>=1e6))?v.toExponential(4):(+v.toPrecision(6)).toString();}
function nearest(arr, t){var lo=0,hi=arr.length-1;if(hi<0)return -1;while(hi-lo>1){var m=(lo+hi)>>1;if(arr[m]<=t)lo=m;else hi=m;}return (Math.abs(arr[hi]-t)<Math.abs(arr[lo]-t))?hi:lo;}

// ---- the crane: one svg per view, to scale (metres; y of the page flipped so up is up)
var P = D.frames.points, F = D.frames.forces, fmax = 0;
for (var f in F) F[f].forEach(function(v){if(v!==null&&Math.abs(v)>fmax)fmax=Math.abs(v);});
var arrowScale = fmax > 0 ? D.arrow / fmax : 0;
function isTop(view){return view==="top"||view==="close-top";}
function coords(view, name, i){var p=P[name];return isTop(view)?[p[0][i],p[2][i]]:[p[0][i],p[1][i]];}
function bounds(view){
  var close=view.indexOf("close")===0, b=[Infinity,Infinity,-Infinity,-Infinity], names=close?D.closeup:Object.keys(P);
  names.forEach(function(name){for (var i=0;i<N;i++){var c=coords(view,name,i);if(c[0]===null||c[1]===null)continue;
    b[0]=Math.min(b[0],c[0]);b[1]=Math.min(b[1],c[1]);b[2]=Math.max(b[2],c[0]);b[3]=Math.max(b[3],c[1]);}});
  D.elements.forEach(function(e){if(view==="side"&&e.kind==="ground"){b[1]=Math.min(b[1],e.y);b[3]=Math.max(b[3],e.y);}});
  if (view==="side" && arrowScale>0) b[1]=Math.min(b[1],b[1]-D.arrow-0.5);
  if (!isFinite(b[0])) b=[-1,-1,1,1];
  var size=Math.max(b[2]-b[0],b[3]-b[1]), pad=close?Math.max(0.1,0.15*size):Math.max(1,0.08*size);
  return [b[0]-pad,b[1]-pad,b[2]+pad,b[3]+pad];
}
function scaleBar(svg, b, scale){
  // a bar of a round length near a fifth of the view's width, at its lower left
  var w=b[2]-b[0], want=Math.min(0.8*w,Math.max(w,b[3]-b[1])/5), step=Math.pow(10,Math.floor(Math.log10(want)));
  var len=[1,2,5,10].map(function(m){return m*step;}).filter(function(v){return v<=want;}).pop()||step;
  var x0=b[0]+0.04*w, y0=-b[1]-0.04*(b[3]-b[1]), tick=0.01*w;
  var g=el("g",{"class":"scalebar-group","data-length":len},svg);
  el("path",{"class":"scalebar",fill:"none",d:"M"+x0+","+(y0-tick)+"V"+y0+"H"+(x0+len)+"V"+(y0-tick)},g);
  var t=el("text",{"class":"scalebar-text",x:x0+len+tick,y:y0},g);t.style.fontSize=(12*scale)+"px";
  t.textContent=(+len.toPrecision(3))+" m";
}
var views = [];
function makeView(view, title){
  var b=bounds(view), w=b[2]-b[0], h=b[3]-b[1], px=(D.threeD||D.closeup.length)?520:720, py=Math.max(160,Math.min(600,px*h/w));
  var box=document.createElement("div");box.className="viewbox";
  var cap=document.createElement("div");cap.className="note";cap.textContent=title;box.appendChild(cap);
  var svg=el("svg",{"class":"view",id:"view-"+view,width:px,height:py,viewBox:[b[0],-b[3],w,h].join(" "),preserveAspectRatio:"xMidYMid meet"});
  box.appendChild(svg);document.getElementById("views").appendChild(box);
  var parts=[], scale=Math.max(w/px,h/py);
  if (view==="close-top") ["hook","payload"].forEach(function(name){
    // seen from above the sway is centimetres: the paths of hook and payload over the whole run
    var pts=[];for(var i=0;i<N;i++){var c=coords(view,name,i);if(c[0]!==null&&c[1]!==null)pts.push(c[0]+","+(-c[1]));}
    el("polyline",{"class":"trail trail-"+name,points:pts.join(" "),fill:"none"},svg);});
  D.elements.forEach(function(e){
    if (isTop(view) && (e.kind==="arrow"||e.kind==="ground")) return;
    if (view==="close" && e.kind==="arrow") return;
    var g={e:e};
    if (e.kind==="ground"){el("line",{"class":"ground",x1:b[0],x2:b[2],y1:-e.y,y2:-e.y},svg);return;}
    if (e.kind==="line") g.n=el("line",{"class":e.cls},svg);
    else if (e.kind==="dot") g.n=el("circle",{"class":e.cls,r:view==="close-top"?4*scale:e.r,id:view==="side"?"drawn-"+e.id:null},svg);
    else if (e.kind==="box" && view==="close-top") g.n=el("circle",{"class":e.cls,r:5*scale},svg);
    else if (e.kind==="box") g.n=el("rect",{"class":e.cls,width:e.w,height:e.h},svg);
    else if (e.kind==="pad") g.n=el("rect",{"class":"pad",width:e.w,height:isTop(view)?e.w:0.15},svg);
    else if (e.kind==="anchor") g.n=el("path",{"class":"anchor"},svg);
    else if (e.kind==="arrow"){g.n=el("path",{"class":"arrow"},svg);g.t=el("text",{},svg);}
    parts.push(g);
  });
  scaleBar(svg, b, Math.max(w/px,h/py));
  views.push({view:view,svg:svg,parts:parts,scale:Math.max(w/px,h/py)});
}
function drawFrame(v, i){
  v.parts.forEach(function(g){
    var e=g.e, n=g.n;
    if (e.kind==="line"){var a=coords(v.view,e.a,i),c=coords(v.view,e.b,i);
      n.setAttribute("x1",a[0]);n.setAttribute("y1",-a[1]);n.setAttribute("x2",c[0]);n.setAttribute("y2",-c[1]);return;}
    var p=coords(v.view,e.at,i);
    if (e.kind==="dot"){n.setAttribute("cx",p[0]);n.setAttribute("cy",-p[1]);}
    else if (e.kind==="box" && v.view==="close-top"){n.setAttribute("cx",p[0]);n.setAttribute("cy",-p[1]);}
    else if (e.kind==="box"){n.setAttribute("x",p[0]-e.w/2);n.setAttribute("y",-p[1]-e.h/2);}
    else if (e.kind==="pad"){n.setAttribute("x",p[0]-e.w/2);n.setAttribute("y",isTop(v.view)?-p[1]-e.w/2:-p[1]);}
    else if (e.kind==="anchor"){var s=0.3;n.setAttribute("d","M"+p[0]+","+(-p[1])+"l"+(-s)+","+(-s)+"h"+(2*s)+"z");}
    else if (e.kind==="arrow"){var f=F[e.force][i]||0, L=f*arrowScale, y0=-p[1]+0.2+L, s=Math.min(0.3,Math.abs(L)/3);
      // the reaction pushes the pad up: the arrow ends at the pad, pointing up
      n.setAttribute("d","M"+p[0]+","+y0+"V"+(-p[1]+0.2)+"m"+(-s)+","+s+"l"+s+","+(-s)+"l"+s+","+s);
      // labels of the front pads to the left of their arrow, the rear pads' to the right, one row per pad
      g.t.setAttribute("x",p[0]+(e.side<0?-0.15:0.15));g.t.setAttribute("text-anchor",e.side<0?"end":"start");
      g.t.setAttribute("y",-p[1]+0.2+D.arrow*0.5+(e.row||0)*14*v.scale);g.t.style.fontSize=(12*v.scale)+"px";
      g.t.textContent=e.label+" "+fixed(f/1e3,1)+" kN";}
  });
}

// ---- plots: svg polylines of the decimated series, hover values, a cursor at the slider's time, drag to zoom
var plots = [], W=720, H=200, L0=70, R0=10, T0=10, B0=36;
function ticks(lo, hi, n){var span=hi-lo;if(!(span>0))return [lo];var step=Math.pow(10,Math.floor(Math.log10(span/n)));
  [1,2,5,10].some(function(m){if(span/(step*m)<=n){step*=m;return true;}return false;});
  var out=[];for(var v=Math.ceil(lo/step)*step;v<=hi+step*1e-9;v+=step)out.push(Math.abs(v)<step*1e-9?0:v);
  out.decimals=Math.max(0,-Math.floor(Math.log10(step)+1e-9));return out;}
var COLORS=["#1f77b4","#d62728","#2ca02c","#9467bd","#ff7f0e","#8c564b","#17becf","#7f7f7f"];
function makePlot(spec, idx){
  var box=document.createElement("div");box.className="plot";
  var h3=document.createElement("div");h3.innerHTML="<b></b>";h3.firstChild.textContent=spec.title;box.appendChild(h3);
  var svg=el("svg",{width:W,height:H,id:"plot-"+idx},null);box.appendChild(svg);
  var tip=document.createElement("div");tip.className="tip";box.appendChild(tip);
  document.getElementById("plots").appendChild(box);
  var p={spec:spec,svg:svg,tip:tip,t0:D.t0,t1:D.t1};
  svg.addEventListener("mousemove",function(ev){hover(p,ev);});
  svg.addEventListener("mousedown",function(ev){p.drag=xToT(p,ev.offsetX);});
  svg.addEventListener("mouseup",function(ev){var t=xToT(p,ev.offsetX);
    if(p.drag!==undefined&&Math.abs(t-p.drag)>(p.t1-p.t0)*0.01){p.t0=Math.min(t,p.drag);p.t1=Math.max(t,p.drag);render(p);}
    else seek(nearest(T,t));p.drag=undefined;});
  svg.addEventListener("dblclick",function(){p.t0=D.t0;p.t1=D.t1;render(p);});
  plots.push(p);render(p);
}
function xToT(p,x){return p.t0+(x-L0)/(W-L0-R0)*(p.t1-p.t0);}
function render(p){
  var svg=p.svg;while(svg.firstChild)svg.removeChild(svg.firstChild);
  var legend=layoutLegend(p), marks=p.spec.marks||[], top=T0+legend.height+12*marks.length;
  var lo=Infinity,hi=-Infinity;
  p.spec.series.forEach(function(s){for(var k=0;k<s.t.length;k++){if(s.t[k]<p.t0||s.t[k]>p.t1||s.v[k]===null)continue;lo=Math.min(lo,s.v[k]);hi=Math.max(hi,s.v[k]);}});
  (p.spec.lines||[]).forEach(function(r){lo=Math.min(lo,r.v);hi=Math.max(hi,r.v);});
  if(!isFinite(lo)){lo=0;hi=1;}if(hi-lo<1e-12*Math.max(1,Math.abs(hi))){lo-=0.5*Math.max(1e-9,Math.abs(lo)||1);hi+=0.5*Math.max(1e-9,Math.abs(hi)||1);}
  var m=0.05*(hi-lo);lo-=m;hi+=m;p.lo=lo;p.hi=hi;
  var X=function(t){return L0+(t-p.t0)/((p.t1-p.t0)||1)*(W-L0-R0);}, Y=function(v){return top+(hi-v)/(hi-lo)*(H-top-B0);};
  p.X=X;
  var yt=ticks(lo,hi,5), tt=ticks(p.t0,p.t1,8);
  yt.forEach(function(v){el("line",{"class":"grid",x1:L0,x2:W-R0,y1:Y(v),y2:Y(v)},svg);
    el("text",{x:L0-4,y:Y(v)+4,"text-anchor":"end","class":"ytick"},svg).textContent=fixed(v,yt.decimals);});
  tt.forEach(function(t){el("text",{x:X(t),y:H-B0+14,"text-anchor":"middle"},svg).textContent=fixed(t,tt.decimals);});
  el("line",{"class":"axis",x1:L0,x2:L0,y1:top,y2:H-B0},svg);el("line",{"class":"axis",x1:L0,x2:W-R0,y1:H-B0,y2:H-B0},svg);
  el("text",{x:(L0+W)/2,y:H-4,"text-anchor":"middle"},svg).textContent="time [s]";
  el("text",{x:12,y:(H-B0+top)/2,"text-anchor":"middle",transform:"rotate(-90 12 "+(H-B0+top)/2+")"},svg).textContent=p.spec.ylabel;
  (p.spec.lines||[]).forEach(function(r){el("line",{x1:L0,x2:W-R0,y1:Y(r.v),y2:Y(r.v),stroke:"#888","stroke-dasharray":"4 3"},svg);
    el("text",{x:W-R0-2,y:Y(r.v)-3,"text-anchor":"end",fill:"#666"},svg).textContent=r.label;});
  marks.forEach(function(m,k){if(m.t<p.t0||m.t>p.t1)return;var x=X(m.t), right=x>(L0+W)/2;
    // an event (a command started or stopped, an emergency stop) or where the run stopped: a vertical line,
    // its label in a row of its own between the legend and the plot area
    el("line",{"class":"mark",x1:x,x2:x,y1:top-12*(marks.length-k)+2,y2:H-B0},svg);
    var tx=el("text",{"class":"mark-label",x:right?x-3:x+3,y:T0+legend.height+10+12*k,"text-anchor":right?"end":"start"},svg);
    tx.textContent=m.label+" (t = "+fmt(m.t)+" s)";var w=tx.getComputedTextLength();   // kept inside the plot
    if(!right&&x+3+w>W-R0)tx.setAttribute("x",Math.max(L0,W-R0-w));if(right&&x-3-w<L0)tx.setAttribute("x",Math.min(W-R0,L0+w));});
  // commands (dashed) drawn last: over the output they drive, which they often cover exactly
  var order=p.spec.series.map(function(s,k){return k;}).sort(function(a,b){return (p.spec.series[a].dash?1:0)-(p.spec.series[b].dash?1:0)||a-b;});
  order.forEach(function(k){var s=p.spec.series[k], pts=[];for(var j=0;j<s.t.length;j++){if(s.v[j]===null||s.t[j]<p.t0||s.t[j]>p.t1)continue;pts.push(X(s.t[j]).toFixed(1)+","+Y(s.v[j]).toFixed(1));}
    el("polyline",{points:pts.join(" "),fill:"none",stroke:COLORS[k%COLORS.length],"stroke-width":s.dash?2:1.3,
      "stroke-dasharray":s.dash?"7 4":null,"class":s.dash?"command":null},svg);});
  legend.place(svg);
  p.cursor=el("line",{"class":"cursor",y1:top,y2:H-B0},svg);placeCursor(p);
}
function layoutLegend(p){
  // the series' names in rows above the plot area, inside the svg: each entry measured, a row wrapped
  // before it would pass the right edge (the svg's data-legend-right records the widest row's end)
  var svg=p.svg, x=L0+8, row=0, items=[], right=0;
  p.spec.series.forEach(function(s,k){
    var t=el("text",{"class":"legend",fill:COLORS[k%COLORS.length]},svg);t.textContent=s.name;
    var w=t.getComputedTextLength();svg.removeChild(t);
    if (x+w>W-R0 && x>L0+8){row++;x=L0+8;}
    items.push({k:k,name:s.name,x:x,row:row});right=Math.max(right,x+w);x+=w+16;});
  var height=items.length?(row+1)*14:0;
  return {height:height,place:function(svg){
    items.forEach(function(it){el("text",{"class":"legend",x:it.x,y:T0+11+14*it.row,fill:COLORS[it.k%COLORS.length]},svg).textContent=it.name;});
    svg.setAttribute("data-legend-right",right.toFixed(1));svg.setAttribute("width",W);}};
}
function placeCursor(p){var x=p.X(T[frame]);p.cursor.setAttribute("x1",x);p.cursor.setAttribute("x2",x);
  p.cursor.setAttribute("visibility",(T[frame]>=p.t0&&T[frame]<=p.t1)?"visible":"hidden");
  // the values at the slider's time (each series' sample nearest to it), shown under the plot and kept in
  // data-cursor (JSON: series name -> value in the axis' unit) with data-cursor-t
  var t=T[frame], parts=["t = "+fmt(t)+" s"], at={};
  p.spec.series.forEach(function(s){var k=nearest(s.t,t);if(k<0)return;at[s.name]=s.v[k];parts.push(s.name+" = "+fmt(s.v[k])+" "+p.spec.unit);});
  p.svg.setAttribute("data-cursor-t",t);p.svg.setAttribute("data-cursor",JSON.stringify(at));p.tip.textContent=parts.join("; ");}
function hover(p, ev){var t=xToT(p,ev.offsetX), parts=["t = "+fmt(t)+" s"];
  p.spec.series.forEach(function(s){var k=nearest(s.t,t);if(k>=0)parts.push(s.name+" = "+fmt(s.v[k])+" "+p.spec.unit);});
  p.tip.textContent=parts.join("; ");}

// ---- the slider, play/pause and #t= in the address
var slider=document.getElementById("slider"), readout=document.getElementById("time");
function seek(i){
  frame=Math.max(0,Math.min(N-1,i));slider.value=frame;
  views.forEach(function(v){drawFrame(v,frame);});
  plots.forEach(placeCursor);
  readout.textContent="t = "+fmt(T[frame])+" s (frame "+(frame+1)+" of "+N+")";
  views.forEach(function(v){v.parts.forEach(function(g){if(g.e.kind==="line"&&g.e.cls==="boom"){
    v.svg.setAttribute("data-boom-tip",g.n.getAttribute("x2")+","+(-g.n.getAttribute("y2")));
    v.svg.setAttribute("data-boom-foot",g.n.getAttribute("x1")+","+(-g.n.getAttribute("y1")));}});});
  var side=document.getElementById("view-side"), hook=document.getElementById("drawn-hook");
  side.setAttribute("data-frame",frame);side.setAttribute("data-t",T[frame]);
  if(hook){side.setAttribute("data-hook-x",hook.getAttribute("cx"));side.setAttribute("data-hook-y",-hook.getAttribute("cy"));}
}
function fromHash(){var m=/t=([-+0-9.eE]+)/.exec(location.hash);if(m)seek(nearest(T,parseFloat(m[1])));}
document.getElementById("play").addEventListener("click",function(){
  if(playing){clearInterval(playing);playing=null;this.textContent="play";return;}
  this.textContent="pause";var start=performance.now(), t0=T[frame>=N-1?0:frame];
  playing=setInterval(function(){var t=t0+(performance.now()-start)/1000*D.speed;
    if(t>=T[N-1]){seek(N-1);document.getElementById("play").click();return;}seek(nearest(T,t));},40);
});
slider.max=N-1;slider.addEventListener("input",function(){seek(+slider.value);});
window.addEventListener("hashchange",fromHash);
makeView("side", "side view (x right, y up) [m], to scale");
if (D.threeD) makeView("top", "top view (x right, z up) [m], to scale");
if (D.closeup.length) makeView("close", "close-up of "+D.closeup.join(", ").replace(/_/g," ")+", side view [m], to scale");
if (D.closeup.length && D.threeD) makeView("close-top", "close-up from above (x, z) [m]: hook, payload, their paths");
D.plots.forEach(makePlot);
seek(0);fromHash();
document.body.setAttribute("data-ready","1");
})();
"""
