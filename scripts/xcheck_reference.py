"""Independent cross-check of the CPU reference rasterizer, written from the RC text and the
3DGS forward pass in plain Python (f64, no shared code): a seeded random INRIA PLY is rendered
by `splatgl render --backend reference` to PFM and recomputed here pixel by pixel.

Usage: python3 scripts/xcheck_reference.py PATH/TO/splatgl [WORKDIR]
Exit status 0 when every channel of every pixel agrees within 1e-5, 1 otherwise.
"""
import math, os, random, struct, subprocess, sys, tempfile

exe = os.path.abspath(sys.argv[1])
work = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="splatgl-xcheck-")
os.chdir(work)
random.seed(5)
N=40; W,H=48,32; FOV=math.radians(60)
deg=1
K=(deg+1)**2-1
spl=[]
for i in range(N):
    p=[random.uniform(-1,1),random.uniform(-1,1),random.uniform(-1,1)]
    ls=[math.log(random.uniform(0.02,0.3)) for _ in range(3)]
    q=[random.uniform(-1,1) for _ in range(4)]  # w x y z (unnormalised)
    lo=random.uniform(-2,4)
    dc=[random.uniform(-1.5,1.5) for _ in range(3)]
    rest=[random.uniform(-0.5,0.5) for _ in range(3*K)]
    spl.append((p,ls,q,lo,dc,rest))
props=["x","y","z","f_dc_0","f_dc_1","f_dc_2"]+[f"f_rest_{i}" for i in range(3*K)]+["opacity","scale_0","scale_1","scale_2","rot_0","rot_1","rot_2","rot_3"]
hdr="ply\nformat binary_little_endian 1.0\nelement vertex %d\n"%N+"".join("property float %s\n"%p for p in props)+"end_header\n"
body=b""
f32=lambda v: struct.unpack('<f',struct.pack('<f',v))[0]
stored=[]
for (p,ls,q,lo,dc,rest) in spl:
    row=p+dc+rest+[lo]+ls+q
    row=[f32(v) for v in row]
    stored.append(row)
    body+=struct.pack('<%df'%len(row),*row)
open("s.ply","wb").write(hdr.encode()+body)
eye=(0.3,0.5,3.0); tgt=(0.0,0.0,0.0)
subprocess.run([exe,"render","s.ply","--backend","reference","--look-at","%g,%g,%g,%g,%g,%g,0,1,0"%(eye+tgt),"--width",str(W),"--height",str(H),"--fov","60","-o","out.pfm"],check=True)
# --- independent implementation (f64) ---
def sub(a,b): return [a[i]-b[i] for i in range(3)]
def dot(a,b): return sum(a[i]*b[i] for i in range(3))
def cross(a,b): return [a[1]*b[2]-a[2]*b[1],a[2]*b[0]-a[0]*b[2],a[0]*b[1]-a[1]*b[0]]
def norm(a):
    l=math.sqrt(dot(a,a)); return [x/l for x in a]
fwd=norm(sub(tgt,eye)); right=norm(cross(fwd,[0,1,0])); down=cross(fwd,right)
R=[right,down,fwd]  # rows: camera axes
def w2c(p):
    d=sub(p,eye); return [dot(R[0],d),dot(R[1],d),dot(R[2],d)]
fy=0.5*H/math.tan(FOV/2); fx=fy; cx=W/2; cy=H/2
tanx=0.5*W/fx; tany=0.5*H/fy
C0=0.28209479177387814; C1=0.4886025119029199
items=[]
for idx,row in enumerate(stored):
    p=row[0:3]; dc=row[3:6]; rest=row[6:6+3*K]; lo=row[6+3*K]; ls=row[7+3*K:10+3*K]; qw,qx,qy,qz=row[10+3*K:14+3*K]
    n=math.sqrt(qw*qw+qx*qx+qy*qy+qz*qz); qw,qx,qy,qz=qw/n,qx/n,qy/n,qz/n
    s=[math.exp(v) for v in ls]
    op=1/(1+math.exp(-lo))
    Rm=[[1-2*(qy*qy+qz*qz),2*(qx*qy-qw*qz),2*(qx*qz+qw*qy)],
        [2*(qx*qy+qw*qz),1-2*(qx*qx+qz*qz),2*(qy*qz-qw*qx)],
        [2*(qx*qz-qw*qy),2*(qy*qz+qw*qx),1-2*(qx*qx+qy*qy)]]
    M=[[Rm[i][j]*s[j] for j in range(3)] for i in range(3)]
    Sig=[[sum(M[i][k]*M[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    t=w2c(p)
    if t[2]<=0.2: continue
    xz=max(-1.3*tanx,min(1.3*tanx,t[0]/t[2])); yz=max(-1.3*tany,min(1.3*tany,t[1]/t[2]))
    J=[[fx/t[2],0,-fx*xz/t[2]],[0,fy/t[2],-fy*yz/t[2]]]
    JW=[[sum(J[a][k]*R[k][b] for k in range(3)) for b in range(3)] for a in range(2)]
    cov=[[sum(JW[a][i]*Sig[i][j]*JW[b][j] for i in range(3) for j in range(3)) for b in range(2)] for a in range(2)]
    a=cov[0][0]+0.3; b=cov[0][1]; c=cov[1][1]+0.3
    det=a*c-b*b
    u=fx*t[0]/t[2]+cx; v=fy*t[1]/t[2]+cy
    d=norm(sub(p,eye)); x,y,z=d
    col=[]
    for ch in range(3):
        val=C0*dc[ch]
        if deg>=1:
            r=[rest[ch*K+j] for j in range(K)]
            val+=-C1*y*r[0]+C1*z*r[1]-C1*x*r[2]
        col.append(max(val+0.5,0))
    key=dot(sub(p,eye),sub(p,eye))
    items.append((key,idx,u,v,c/det,-b/det,a/det,op,col))
items.sort(key=lambda it:(-it[0],it[1]))
img=[[[0.0,0.0,0.0] for _ in range(W)] for _ in range(H)]
for (key,idx,u,v,A,B,Cc,op,col) in items:
    for py in range(H):
        for px in range(W):
            dx=px+0.5-u; dy=py+0.5-v
            m2=A*dx*dx+2*B*dx*dy+Cc*dy*dy
            if m2>9 or m2<0: continue
            al=min(0.99,op*math.exp(-0.5*m2))
            if al<1/255: continue
            for ch in range(3):
                img[py][px][ch]=col[ch]*al+img[py][px][ch]*(1-al)
# read PFM
data=open("out.pfm","rb").read()
parts=data.split(b"\n",3)
w,h=map(int,parts[1].split()); scale=float(parts[2])
vals=struct.unpack('<%df'%(w*h*3),parts[3][:w*h*12])
maxd=0
for yy in range(h):
    for xx in range(w):
        k=((h-1-yy)*w+xx)*3
        for ch in range(3):
            maxd=max(maxd,abs(vals[k+ch]-img[yy][xx][ch]))
ok = maxd <= 1e-5
print("xcheck: reference vs independent Python, %d splats %dx%d, max abs diff %.3g (tolerance 1e-5)" % (N, W, H, maxd))
print("xcheck: %d passed, %d failed" % (1 if ok else 0, 0 if ok else 1))
sys.exit(0 if ok else 1)
