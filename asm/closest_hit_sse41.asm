; Closest hit of one ray against a run of spheres, 4 spheres per step
; (SSE4.1, legacy encoding: runs on any x86-64 with SSE4.1). Computes exactly
; what ptr_closest_hit_c computes, in the same order and with the same IEEE
; operations, so the results are bit-identical.

%include "ptr.inc"
%include "layout.inc"

section .rodata
align 16
lane_index: dd 0, 1, 2, 3
lane_step:  times 4 dd 4
sign_mask:  times 4 dd 0x80000000

section .text

; Broadcast copies of the ray origin live in the red zone below rsp.
ORG_X equ -64
ORG_Y equ -48
ORG_Z equ -32

; A register with the float at [rdi + %2] in every lane.
%macro BROADCAST 2 ; register, ray offset
    movss       %1, [rdi + %2]
    shufps      %1, %1, 0
%endmacro

; One step over 4 spheres at index rax. %1 = 1 for the last, partial step:
; lanes at or past the count are masked off. Memory operands of legacy SSE
; arithmetic must be 16-byte aligned: the sphere arrays are 64-byte aligned.
%macro STEP 1
    movups      xmm8, [rsp + ORG_X]
    subps       xmm8, [r8 + rax*4]              ; fx = ox - cx
    movups      xmm9, [rsp + ORG_Y]
    subps       xmm9, [r9 + rax*4]              ; fy
    movups      xmm10, [rsp + ORG_Z]
    subps       xmm10, [r10 + rax*4]            ; fz
    movaps      xmm11, xmm8
    mulps       xmm11, xmm0
    movaps      xmm12, xmm9
    mulps       xmm12, xmm1
    addps       xmm11, xmm12
    movaps      xmm12, xmm10
    mulps       xmm12, xmm2
    addps       xmm11, xmm12                    ; b = f.d
    movaps      xmm12, xmm11
    mulps       xmm12, xmm0
    movaps      xmm13, xmm8
    subps       xmm13, xmm12
    mulps       xmm13, xmm13                    ; vx^2, vx = fx - b dx
    movaps      xmm12, xmm11
    mulps       xmm12, xmm1
    movaps      xmm14, xmm9
    subps       xmm14, xmm12
    mulps       xmm14, xmm14
    addps       xmm13, xmm14                    ; + vy^2
    movaps      xmm12, xmm11
    mulps       xmm12, xmm2
    movaps      xmm14, xmm10
    subps       xmm14, xmm12
    mulps       xmm14, xmm14
    addps       xmm13, xmm14                    ; |v|^2
    movaps      xmm12, [r11 + rax*4]
    mulps       xmm12, xmm12                    ; r^2
    movaps      xmm14, xmm12
    subps       xmm14, xmm13                    ; disc = r^2 - |v|^2
    xorps       xmm13, xmm13
    cmpleps     xmm13, xmm14                    ; 0 <= disc (NaN radius: no)
%if %1
    movd        xmm15, edx
    pshufd      xmm15, xmm15, 0
    pcmpgtd     xmm15, xmm6                     ; index < count
    andps       xmm13, xmm15
%endif
    ptest       xmm13, xmm13
    jz          %%done                          ; no lane can hit: skip sqrt, div
    mulps       xmm8, xmm8
    mulps       xmm9, xmm9
    addps       xmm8, xmm9
    mulps       xmm10, xmm10
    addps       xmm8, xmm10
    subps       xmm8, xmm12                     ; c = f.f - r^2
    sqrtps      xmm14, xmm14
    movaps      xmm9, xmm7
    andps       xmm9, xmm11
    movaps      xmm10, xmm7
    andnps      xmm10, xmm14
    orps        xmm10, xmm9                     ; copysign(sqrt(disc), b)
    xorps       xmm11, xmm7
    subps       xmm11, xmm10                    ; q = -b - copysign(...)
    divps       xmm8, xmm11                     ; t0 = c / q
    movaps      xmm9, xmm8
    minps       xmm9, xmm11                     ; near = t0 < q ? t0 : q
    maxps       xmm8, xmm11                     ; far  = t0 > q ? t0 : q
    movaps      xmm10, xmm3
    cmpltps     xmm10, xmm9                     ; tmin < near
    andps       xmm9, xmm10
    andnps      xmm10, xmm8
    orps        xmm9, xmm10                     ; t = near > tmin ? near : far
    movaps      xmm10, xmm3
    cmpltps     xmm10, xmm9
    andps       xmm13, xmm10                    ; t > tmin
    movaps      xmm10, xmm9
    cmpltps     xmm10, xmm4
    andps       xmm13, xmm10                    ; t < best (strict: first index wins)
    andps       xmm9, xmm13
    movaps      xmm10, xmm13
    andnps      xmm10, xmm4
    orps        xmm9, xmm10
    movaps      xmm4, xmm9                      ; best t
    movaps      xmm10, xmm13
    andps       xmm10, xmm6
    andnps      xmm13, xmm5
    orps        xmm13, xmm10
    movaps      xmm5, xmm13                     ; best index
%%done:
    paddd       xmm6, [lane_step]
%endmacro

; int ptr_closest_hit_sse41(const PtrRay *ray, const PtrSpheres *spheres,
;                           size_t count, PtrHit *hit);
;
; rdi ray, rsi spheres, rdx count, rcx hit (moved to rsi once the sphere
; pointers are loaded; rcx then holds the end of the whole steps)
; r8 cx, r9 cy, r10 cz, r11 radius, rax sphere index
; xmm0-2 dx, dy, dz   xmm3 tmin   xmm4 best t per lane   xmm5 best index per lane
; xmm6 lane indices   xmm7 sign mask   xmm8-15 scratch
; [rsp-64], [rsp-48], [rsp-32]: ox, oy, oz broadcast (red zone)
FUNCTION ptr_closest_hit_sse41
    LOAD_SPHERE_POINTERS
    BROADCAST   xmm8, RAY_ORG_X
    movups      [rsp + ORG_X], xmm8
    BROADCAST   xmm8, RAY_ORG_Y
    movups      [rsp + ORG_Y], xmm8
    BROADCAST   xmm8, RAY_ORG_Z
    movups      [rsp + ORG_Z], xmm8
    BROADCAST   xmm0, RAY_DIR_X
    BROADCAST   xmm1, RAY_DIR_Y
    BROADCAST   xmm2, RAY_DIR_Z
    BROADCAST   xmm3, RAY_TMIN
    BROADCAST   xmm4, RAY_TMAX
    pcmpeqd     xmm5, xmm5                      ; PTR_NO_HIT in every lane
    movdqa      xmm6, [lane_index]
    movaps      xmm7, [sign_mask]
    STEP_LOOP   4
    ; The smallest t over the lanes, then the lowest index among the lanes
    ; that hold it: the sphere a sequential scan with a strict < would keep.
    movaps      xmm8, xmm4
    shufps      xmm8, xmm8, 0x4e
    minps       xmm8, xmm4
    movaps      xmm9, xmm8
    shufps      xmm9, xmm9, 0xb1
    minps       xmm8, xmm9                      ; the minimum, in every lane
    movaps      xmm9, xmm4
    cmpeqps     xmm9, xmm8
    pcmpeqd     xmm10, xmm10
    pxor        xmm9, xmm10
    por         xmm9, xmm5                      ; index where t is the minimum, else ~0
    pshufd      xmm10, xmm9, 0x4e
    pminud      xmm9, xmm10
    pshufd      xmm10, xmm9, 0xb1
    pminud      xmm9, xmm10
    movss       [rsi + HIT_T], xmm8
    movd        ecx, xmm9
    mov         [rsi + HIT_SPHERE], ecx
    xor         eax, eax
    cmp         ecx, -1
    setne       al
    ret

section .note.GNU-stack noalloc noexec nowrite progbits
