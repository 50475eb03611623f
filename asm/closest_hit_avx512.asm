; Closest hit of one ray against a run of spheres, 16 spheres per step
; (AVX-512 F only: no DQ or VL instructions). Computes exactly what
; ptr_closest_hit_c computes, in the same order and with the same IEEE
; operations, so the results are bit-identical.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"

section .rodata
align 64
lane_index: dd 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15
lane_step:  times 16 dd 16
sign_mask:  times 16 dd 0x80000000

section .text

; One step over 16 spheres at index rax. %1 = 1 for the last, partial step:
; lanes at or past the count are masked off.
%macro STEP 1
    vsubps      zmm8, zmm16, [r8 + rax*4]       ; fx = ox - cx
    vsubps      zmm9, zmm17, [r9 + rax*4]       ; fy
    vsubps      zmm10, zmm18, [r10 + rax*4]     ; fz
    DISCRIMINANT z, vmovups
    vcmpps      k1, zmm12, zmm20, CMP_GE_OQ     ; disc >= 0 (NaN radius: no)
%if %1
    vpcmpgtd    k2, zmm19, zmm6                 ; index < count
    kandw       k1, k1, k2
%endif
    kortestw    k1, k1
    jz          %%done                          ; no lane can hit: skip sqrt, div
    OFFSET_TERM z
    vsqrtps     zmm12, zmm12
    vpandd      zmm9, zmm11, zmm7
    vpandnd     zmm12, zmm7, zmm12
    vpord       zmm12, zmm12, zmm9              ; copysign(sqrt(disc), b)
    vpxord      zmm11, zmm11, zmm7
    vsubps      zmm11, zmm11, zmm12             ; q = -b - copysign(...)
    vdivps      zmm8, zmm8, zmm11               ; t0 = c / q
    vminps      zmm9, zmm8, zmm11               ; near = t0 < q ? t0 : q
    vmaxps      zmm10, zmm8, zmm11              ; far  = t0 > q ? t0 : q
    vcmpps      k2, zmm9, zmm3, CMP_GT_OQ
    vblendmps   zmm9{k2}, zmm10, zmm9           ; t = near > tmin ? near : far
    vcmpps      k1{k1}, zmm9, zmm3, CMP_GT_OQ   ; t > tmin
    vcmpps      k1{k1}, zmm9, zmm4, CMP_LT_OQ   ; t < best (strict: first index wins)
    vmovaps     zmm4{k1}, zmm9
    vmovdqa32   zmm5{k1}, zmm6
%%done:
    vpaddd      zmm6, zmm6, [lane_step]
%endmacro

; int ptr_closest_hit_avx512(const PtrRay *ray, const PtrSpheres *spheres,
;                            size_t count, PtrHit *hit);
;
; rdi ray, rsi spheres, rdx count, rcx hit (moved to rsi once the sphere
; pointers are loaded; rcx then holds the end of the whole steps)
; r8 cx, r9 cy, r10 cz, r11 radius, rax sphere index
; zmm0-2 dx, dy, dz   zmm3 tmin   zmm4 best t per lane   zmm5 best index per lane
; zmm6 lane indices   zmm7 sign mask   zmm8-13 scratch
; zmm16-18 ox, oy, oz   zmm19 count   zmm20 zero   k1, k2 lane masks
FUNCTION ptr_closest_hit_avx512
    LOAD_SPHERE_POINTERS
    vbroadcastss zmm16, [rdi + RAY_ORG_X]
    vbroadcastss zmm17, [rdi + RAY_ORG_Y]
    vbroadcastss zmm18, [rdi + RAY_ORG_Z]
    vbroadcastss zmm0, [rdi + RAY_DIR_X]
    vbroadcastss zmm1, [rdi + RAY_DIR_Y]
    vbroadcastss zmm2, [rdi + RAY_DIR_Z]
    vbroadcastss zmm3, [rdi + RAY_TMIN]
    vbroadcastss zmm4, [rdi + RAY_TMAX]
    vpternlogd  zmm5, zmm5, zmm5, 0xff          ; PTR_NO_HIT in every lane
    vmovdqu32   zmm6, [lane_index]
    vmovdqu32   zmm7, [sign_mask]
    vpbroadcastd zmm19, edx
    vpxord      zmm20, zmm20, zmm20
    STEP_LOOP   16
    ; The smallest t over the lanes, then the lowest index among the lanes
    ; that hold it: the sphere a sequential scan with a strict < would keep.
    vextractf64x4 ymm8, zmm4, 1
    vminps      ymm8, ymm8, ymm4
    vextractf128 xmm9, ymm8, 1
    vminps      xmm8, xmm8, xmm9
    HORIZONTAL_MIN_XMM8                         ; the minimum, in every lane
    vbroadcastss zmm9, xmm8
    vcmpps      k1, zmm4, zmm9, CMP_EQ_OQ
    vpternlogd  zmm10, zmm10, zmm10, 0xff
    vmovdqa32   zmm10{k1}, zmm5                 ; index where t is the minimum, else ~0
    vextracti64x4 ymm11, zmm10, 1
    vpminud     ymm10, ymm10, ymm11
    vextracti128 xmm11, ymm10, 1
    vpminud     xmm10, xmm10, xmm11
    STORE_HIT_AND_RETURN

section .note.GNU-stack noalloc noexec nowrite progbits
