; Closest hits of 8 rays, one per lane, in the tree (src/accel/bvh.h),
; AVX-512 (F and VL, on ymm registers): the rays go down the tree together,
; each node's children tested one at a time against all eight rays, each
; leaf's spheres one at a time against all eight. Coherent rays (a pixel's
; camera rays) visit nearly the same nodes, so the packet walks the tree once
; for all of them, and a leaf's sphere tests are eight independent chains of
; arithmetic instead of one long chain per ray.
;
; Lane k's answer is exactly ptr_bvh_closest_hit_c's for ray k: its box tests
; are the C traversal's operations on its own ray (the planes broadcast to
; the lanes), its sphere tests ptr_sphere_hit's, and it keeps the smallest
; (t, id) over every sphere it reaches, which does not depend on the order of
; the visits. A ray that leaves a child's box out skips it, exactly as alone.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"
%include "bvh.inc"

section .rodata
align 4
sign_mask:      dd 0x80000000
one:            dd 0x3f800000
flt_max:        dd 0x7f7fffff
slack:          dd PTR_BVH_SLACK
infinity:       dd 0x7f800000
minus_infinity: dd 0xff800000
quiet_nan:      dd 0x7fc00000

section .text

; The frame, at rbp: the stack of 64-byte entries (each ray's entry distance
; into the child, NaN for the rays that do not enter it, which fails every
; comparison; the child; its leaf count), each node pushing at most 8; the
; rsp to return with.
ENTRY_SIZE  equ 64
E_CHILD     equ 32
E_COUNT     equ 36
STACK       equ 0
FRAME       equ ENTRY_SIZE * (PTR_BVH_MAX_DEPTH * 7 + 8) + 8

; Tests spheres eax .. eax + ecx - 1 (ecx >= 1) against the rays of mask k1:
; a ray takes a sphere whose (t, position) is below its best,
; lexicographically (positions are below 2^31, so signed compares, and
; PTR_NO_HIT, -1, is below them all: no tie wins before a hit).
; In: r8-r11 cx, cy, cz, radius; ymm0-2 direction; ymm3 tmin;
; ymm4 best t, ymm6 best sphere; ymm7 sign mask; ymm16-18 the
; origin; ymm22 the slack, ymm25 zero. Out: ymm4, ymm6 and ymm24 (best * slack)
; updated. Clobbers rax, rcx, ymm8-15, k2-k4.
test_leaf:
    vsubps      ymm8, ymm16, [r8 + rax*4]{1to8}     ; fx = ox - cx
    vsubps      ymm9, ymm17, [r9 + rax*4]{1to8}     ; fy
    vsubps      ymm10, ymm18, [r10 + rax*4]{1to8}   ; fz
    DISCRIMINANT y, vbroadcastss
    vcmpps      k2{k1}, ymm12, ymm25, CMP_GE_OQ     ; disc >= 0
    kortestw    k2, k2
    jz          .next                               ; no ray can hit: skip sqrt, div
    ROOT_AVX2
    vcmpps      k2{k2}, ymm9, ymm3, CMP_GT_OQ       ; tmin < t
    vpbroadcastd ymm13, eax                         ; the position
    vcmpps      k3, ymm9, ymm4, CMP_EQ_OQ
    vpcmpgtd    k3{k3}, ymm6, ymm13                 ; t == best and position < the best's
    vcmpps      k4, ymm9, ymm4, CMP_LT_OQ
    korw        k3, k3, k4                          ; ... or t < best
    kandw       k2, k2, k3
    vmovaps     ymm4{k2}, ymm9
    vmovdqa32   ymm6{k2}, ymm13
    vmulps      ymm24{k2}, ymm9, ymm22              ; best * slack
.next:
    inc         eax
    dec         ecx
    jnz         test_leaf
    ret

; void ptr_bvh_closest_hit_packet_avx512(const PtrRayPacket *rays,
;                                        const PtrBvh *bvh,
;                                        const PtrSpheres *spheres,
;                                        PtrHitPacket *hits);
;
; rdi rays, rsi bvh (then the node being tested), rdx spheres (then scratch),
; rcx hits (pushed; then scratch)
; r8-r11 cx, cy, cz, radius   r13 nodes   r14 stack top
; r15 the node's child lanes still to test   rbx the nearest child's entry
; rbp the frame
; ymm0-2 dx, dy, dz   ymm3 tmin   ymm4 best t   ymm6 best sphere
; ymm7 sign mask   ymm8-15 scratch   ymm16-18 ox, oy, oz
; ymm19-21 1 / d clamped   ymm22 slack   ymm23 +inf   ymm24 best * slack
; ymm25 zero   ymm26-31 scratch   xmm15 the nearest child's distance   ymm10
; quiet NaN in a node
; k1 the rays at work   k5-k7 the rays whose 1 / d is negative, per axis
FUNCTION ptr_bvh_closest_hit_packet_avx512
    TREE_ENTRY  FRAME, 64
    vmovaps     ymm0, [rdi + PACKET_DIR_X]
    vmovaps     ymm1, [rdi + PACKET_DIR_Y]
    vmovaps     ymm2, [rdi + PACKET_DIR_Z]
    vmovaps     ymm3, [rdi + PACKET_TMIN]
    vmovaps     ymm4, [rdi + PACKET_TMAX]
    vpcmpeqd    ymm6, ymm6, ymm6                ; PTR_NO_HIT
    vbroadcastss ymm7, [sign_mask]
    vmovaps     ymm16, [rdi + PACKET_ORG_X]
    vmovaps     ymm17, [rdi + PACKET_ORG_Y]
    vmovaps     ymm18, [rdi + PACKET_ORG_Z]
    vbroadcastss ymm22, [slack]
    vbroadcastss ymm23, [infinity]
    vmulps      ymm24, ymm4, ymm22
    vpxord      ymm25, ymm25, ymm25
    mov         eax, 0xff
    kmovw       k1, eax                         ; every ray

    ; The huge spheres left out of the tree, by every ray.
    test        rbx, rbx
    jz          .tree
    xor         eax, eax
    mov         ecx, ebx
    call        test_leaf

.tree:
    test        r13, r13
    jz          .finish
    RECIPROCALS_AVX512
    ; The root, entered by every ray.
    lea         r14, [rbp + STACK]
    vbroadcastss ymm8, [minus_infinity]
    vmovaps     [r14], ymm8
    mov         qword [r14 + E_CHILD], 0
    add         r14, ENTRY_SIZE

.pop:
    lea         rax, [rbp + STACK]
    cmp         r14, rax
    je          .finish
    sub         r14, ENTRY_SIZE
    vcmpps      k1, ymm24, [r14], CMP_GE_OQ     ; the rays that entered it before their best
    kortestw    k1, k1
    jz          .pop
    mov         eax, [r14 + E_CHILD]
    mov         ecx, [r14 + E_COUNT]
    test        ecx, ecx
    jz          .node
    call        test_leaf
    jmp         .pop

.node:
    shl         rax, 8                          ; 256-byte nodes
    lea         rsi, [r13 + rax]
    vmovaps     ymm8, [rsi + NODE_LOWER_X]
    vcmpps      k2, ymm8, [rsi + NODE_UPPER_X], CMP_LE_OQ
    kmovw       r15d, k2                        ; the children (empty lanes: lower > upper)
    vmovss      xmm15, [infinity]
    vbroadcastss ymm10, [quiet_nan]
    mov         rbx, r14
.child:
    bsf         ecx, r15d
    btr         r15d, ecx
    ; Each ray's entry and exit of the child's box, as C computes them for
    ; it: the near plane is lower where its 1 / dir has the sign bit clear.
    BOX_ENTRY_EXIT_AVX512 vbroadcastss, + rcx*4, 26, 29
    vcmpps      k2{k1}, ymm26, ymm29, CMP_LE_OQ
    kortestw    k2, k2
    jz          .next_child
    ; Entered by some ray: pushed with NaN for the others, and the child
    ; whose nearest ray enters first is swapped onto the top below.
    vblendmps   ymm27{k2}, ymm23, ymm26         ; +inf for the others, to order by
    vblendmps   ymm26{k2}, ymm10, ymm26
    vmovaps     [r14], ymm26
    mov         eax, [rsi + NODE_CHILD + rcx*4]
    mov         [r14 + E_CHILD], eax
    mov         eax, [rsi + NODE_LEAF_COUNT + rcx*4]
    mov         [r14 + E_COUNT], eax
    vextractf32x4 xmm8, ymm27, 1
    vminps      xmm8, xmm8, xmm27
    HORIZONTAL_MIN_XMM8
    vucomiss    xmm8, xmm15
    jae         .farther
    vmovaps     xmm15, xmm8
    mov         rbx, r14
.farther:
    add         r14, ENTRY_SIZE
.next_child:
    test        r15d, r15d
    jnz         .child
    cmp         rbx, r14
    je          .pop                            ; nothing pushed
    vmovaps     ymm8, [rbx]
    vmovups     xmm9, [rbx + E_CHILD]
    vmovaps     ymm10, [r14 - ENTRY_SIZE]
    vmovups     xmm11, [r14 - ENTRY_SIZE + E_CHILD]
    vmovaps     [rbx], ymm10
    vmovups     [rbx + E_CHILD], xmm11
    vmovaps     [r14 - ENTRY_SIZE], ymm8
    vmovups     [r14 - ENTRY_SIZE + E_CHILD], xmm9
    jmp         .pop

.finish:
    TREE_LEAVE_FRAME FRAME
    vmovaps     [rcx + HITS_T], ymm4
    vmovdqa     [rcx + HITS_SPHERE], ymm6
    TREE_RETURN

section .note.GNU-stack noalloc noexec nowrite progbits
