## hinf_reference.m: an independent H-infinity synthesis of one galvo axis with Octave's control package
## (Debian octave-control; hinfsyn calls SLICOT SB10FD/SB10AD), for test/servo/test_hinf_synthesis.cpp.
## Written for this project. The caller defines beforehand (octave-cli --eval "R = ...; ...; hinf_reference"):
##   R L Kc Jeq B Kr xi wres Kii Tii   the axis (SI units, Ke = Kc) and its current PI
##   W1 W2 W3                          weights as [G0 Ginf w0] (THESIS eq. 3.40-3.41)
##   gamma_fixed                       level of the central controller printed
##   freqs                             pulsations [rad/s] where K is printed
## Prints: "gamma_infimum <g>" (bisection on the fixed-gamma synthesis with a closed-loop stability check, to
## 1e-7 relative) and "K <w> <re> <im>" for the central controller at gamma_fixed.
1;
pkg load control

## G = theta [deg] / i_ref, built from transfer functions (not the state form of the C++ synthesis model):
## omega/i = Kc/(Jeq s + B) + Kr s/(s^2 + 2 xi wres s + wres^2), i/U = 1/(L s + R + Kc omega/i) (back-EMF),
## the current PI Kii (1 + 1/(Tii s)) closed around i/U, then theta = omega/s.
s = tf ("s");
w_per_i = Kc / (Jeq * s + B) + Kr * s / (s^2 + 2 * xi * wres * s + wres^2);
i_per_u = feedback (ss (1 / (L * s + R)), ss (Kc * w_per_i));
current_loop = feedback (ss (Kii * (1 + 1 / (Tii * s))) * i_per_u, 1);
G = minreal (180 / pi * current_loop * ss (w_per_i) * ss (1 / s), 1e-9);
if (rows (G.a) != 6)
  error ("hinf_reference: G has %d states after minreal, 6 expected", rows (G.a));
endif

function W = weight (g)
  ## W = 1/template = (c s + d)/(a s + b)
  G0 = g(1); Ginf = g(2); w0 = g(3);
  a = Ginf * sqrt (abs (G0^2 - 1)); b = G0 * w0 * sqrt (abs (Ginf^2 - 1));
  c = sqrt (abs (G0^2 - 1)); d = w0 * sqrt (abs (Ginf^2 - 1));
  W = ss (tf ([c d], [a b]));
endfunction

## Standard form (THESIS eq. 3.26): inputs (r, d, u), outputs (e1, e2, eps); plant input u + W3 d.
[ag, bg, cg] = ssdata (G);
[a1, b1, c1, d1] = ssdata (weight (W1));
[a2, b2, c2, d2] = ssdata (weight (W2));
[a3, b3, c3, d3] = ssdata (weight (W3));
n = rows (ag);
A = [ag, zeros(n, 2), bg * c3; -b1 * cg, a1, 0, 0; zeros(1, n), 0, a2, 0; zeros(1, n), 0, 0, a3];
Bp = [zeros(n, 1), bg * d3, bg; b1, 0, 0; 0, 0, b2; 0, b3, 0];
Cp = [-d1 * cg, c1, 0, 0; zeros(1, n), 0, c2, 0; -cg, 0, 0, 0];
Dp = [d1, 0, 0; 0, 0, d2; 1, 0, 0];
P = ss (A, Bp, Cp, Dp);

## Infimum of the achievable gamma: the fixed-gamma synthesis ("sub": SB10FD) bisected.
hi = 10;
lo = 0;
while (hi - lo > 1e-7 * hi)
  g = 0.5 * (lo + hi);
  try
    ok = isstable (lft (P, hinfsyn (P, 1, 1, "method", "sub", "gmax", g)));
  catch
    ok = false;
  end_try_catch
  if (ok)
    hi = g;
  else
    lo = g;
  endif
endwhile
printf ("gamma_infimum %.12g\n", hi);

K = hinfsyn (P, 1, 1, "method", "sub", "gmax", gamma_fixed);
for w = freqs
  k = freqresp (K, w);
  printf ("K %.12g %.17g %.17g\n", w, real (k), imag (k));
endfor
