; Closest hit of one ray against a run of spheres, 8 spheres per step (AVX2).
; Computes exactly what ptr_closest_hit_c computes, in the same order and
; with the same IEEE operations, so the results are bit-identical.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"

section .rodata
align 32
lane_index: dd 0, 1, 2, 3, 4, 5, 6, 7
lane_step:  times 8 dd 8
sign_mask:  times 8 dd 0x80000000

section .text

; One step over 8 spheres at index rax. %1 = 1 for the last, partial step:
; lanes at or past the count are masked off.
%macro STEP 1
    OFFSETS_AVX2
    DISCRIMINANT y, vmovups
    vxorps      ymm14, ymm14, ymm14
    vcmpps      ymm14, ymm12, ymm14, CMP_GE_OQ  ; disc >= 0 (NaN radius: no)
%if %1
    vmovd       xmm15, edx
    vpbroadcastd ymm15, xmm15
    vpcmpgtd    ymm15, ymm15, ymm6              ; index < count
    vandps      ymm14, ymm14, ymm15
%endif
    vtestps     ymm14, ymm14
    jz          %%done                          ; no lane can hit: skip sqrt, div
    ROOT_AVX2
    KEEP_NEARER_AVX2
%%done:
    vpaddd      ymm6, ymm6, [lane_step]
%endmacro

; int ptr_closest_hit_avx2(const PtrRay *ray, const PtrSpheres *spheres,
;                          size_t count, PtrHit *hit);
;
; rdi ray, rsi spheres, rdx count, rcx hit (moved to rsi once the sphere
; pointers are loaded; rcx then holds the end of the whole steps)
; r8 cx, r9 cy, r10 cz, r11 radius, rax sphere index
; ymm0-2 dx, dy, dz   ymm3 tmin   ymm4 best t per lane   ymm5 best index per lane
; ymm6 lane indices   ymm7 sign mask   ymm8-15 scratch
FUNCTION ptr_closest_hit_avx2
    LOAD_SPHERE_POINTERS
    vbroadcastss ymm0, [rdi + RAY_DIR_X]
    vbroadcastss ymm1, [rdi + RAY_DIR_Y]
    vbroadcastss ymm2, [rdi + RAY_DIR_Z]
    vbroadcastss ymm3, [rdi + RAY_TMIN]
    vbroadcastss ymm4, [rdi + RAY_TMAX]
    vpcmpeqd    ymm5, ymm5, ymm5                ; PTR_NO_HIT in every lane
    vmovdqu     ymm6, [lane_index]
    vmovups     ymm7, [sign_mask]
    STEP_LOOP   8
    ; The smallest t over the lanes, then the lowest index among the lanes
    ; that hold it: the sphere a sequential scan with a strict < would keep.
    vextractf128 xmm8, ymm4, 1
    vminps      xmm8, xmm8, xmm4
    HORIZONTAL_MIN_XMM8                         ; the minimum, in every lane
    vinsertf128 ymm9, ymm8, xmm8, 1
    vcmpps      ymm9, ymm4, ymm9, CMP_EQ_OQ
    vpcmpeqd    ymm10, ymm10, ymm10
    vpxor       ymm10, ymm9, ymm10
    vpor        ymm10, ymm10, ymm5              ; index where t is the minimum, else ~0
    vextracti128 xmm11, ymm10, 1
    vpminud     xmm10, xmm10, xmm11
    STORE_HIT_AND_RETURN

section .note.GNU-stack noalloc noexec nowrite progbits
